#!/usr/bin/env python3
"""Writes small ASAM OpenDRIVE 1.6 maps (.xodr) for the OpenDRIVE tests, from the standard's
structure (header, road with planView / lanes / laneSection, junction with connections), written
independently of SUMO: nothing here comes from netconvert.

Usage: write_xodr.py KIND OUT.xodr     KIND: straight | curves | junction | broken

- straight: one 600 m road, one driving lane each way (3.5 m).
- curves:   one 1,100 m road of lines, arcs and clothoids (spirals): a left bend of 300 m radius,
            an S-bend; one driving lane each way.
- junction: a T junction of three 200 m arms (the east arm with a 250 m radius bend), one lane
            each way, with the six connecting roads through the junction (two straight, two
            right turns, two left turns, radius 10 m).
- broken:   well-formed XML that is no usable OpenDRIVE map (a road whose planView has no
            geometry), for the error path.
"""
import math
import sys
from xml.sax.saxutils import quoteattr

LANE_WIDTH = 3.5


def spiral_end(x, y, hdg, length, k0, k1, n=2000):
    """End point and heading of a clothoid (curvature linear from k0 to k1), by integration."""
    ds = length / n
    for i in range(n):
        s = (i + 0.5) * ds
        k = k0 + (k1 - k0) * s / length
        h = hdg + k0 * s + 0.5 * (k1 - k0) * s * s / length
        x += math.cos(h) * ds
        y += math.sin(h) * ds
    return x, y, hdg + k0 * length + 0.5 * (k1 - k0) * length


def plan_view(x, y, hdg, pieces):
    """pieces: ("line", L) | ("arc", L, k) | ("spiral", L, k0, k1). Returns (xml, length, end)."""
    out, s = [], 0.0
    for p in pieces:
        kind, length = p[0], p[1]
        head = f'      <geometry s="{s:.6f}" x="{x:.6f}" y="{y:.6f}" hdg="{hdg:.9f}" length="{length:.6f}">'
        if kind == "line":
            out.append(head + "<line/></geometry>")
            x, y = x + length * math.cos(hdg), y + length * math.sin(hdg)
        elif kind == "arc":
            k = p[2]
            out.append(head + f'<arc curvature="{k:.9f}"/></geometry>')
            h1 = hdg + k * length
            x, y = x + (math.sin(h1) - math.sin(hdg)) / k, y - (math.cos(h1) - math.cos(hdg)) / k
            hdg = h1
        else:
            k0, k1 = p[2], p[3]
            out.append(head + f'<spiral curvStart="{k0:.9f}" curvEnd="{k1:.9f}"/></geometry>')
            x, y, hdg = spiral_end(x, y, hdg, length, k0, k1)
        s += length
    return "\n".join(out), s, (x, y, hdg)


def lane(lane_id, pred=None, succ=None):
    links = ""
    if pred is not None:
        links += f'<predecessor id="{pred}"/>'
    if succ is not None:
        links += f'<successor id="{succ}"/>'
    return (f'          <lane id="{lane_id}" type="driving" level="false"><link>{links}</link>'
            f'<width sOffset="0" a="{LANE_WIDTH}" b="0" c="0" d="0"/>'
            f'<roadMark sOffset="0" type="solid" weight="standard" color="standard" width="0.12"/></lane>')


def road(rid, x, y, hdg, pieces, junction=-1, link="", left=True, lane_links=None):
    """A road with one right lane (-1, driving along the reference line) and, if `left`, one left
    lane (1, driving against it). lane_links: {lane id: (pred, succ)}."""
    geometry, length, end = plan_view(x, y, hdg, pieces)
    lane_links = lane_links or {}
    left_xml = (f"        <left>\n{lane(1, *lane_links.get(1, (None, None)))}\n        </left>\n"
                if left else "")
    xml = f'''  <road name={quoteattr("road " + str(rid))} length="{length:.6f}" id="{rid}" junction="{junction}">
    <link>{link}</link>
    <type s="0" type="rural"><speed max="50" unit="km/h"/></type>
    <planView>
{geometry}
    </planView>
    <elevationProfile><elevation s="0" a="0" b="0" c="0" d="0"/></elevationProfile>
    <lateralProfile/>
    <lanes>
      <laneSection s="0">
{left_xml}        <center>
          <lane id="0" type="none" level="false"><link/><roadMark sOffset="0" type="broken" weight="standard" color="standard" width="0.12"/></lane>
        </center>
        <right>
{lane(-1, *lane_links.get(-1, (None, None)))}
        </right>
      </laneSection>
    </lanes>
  </road>'''
    return xml, end


def document(name, body):
    return f'''<?xml version="1.0" encoding="UTF-8"?>
<OpenDRIVE>
  <header revMajor="1" revMinor="6" name={quoteattr(name)} version="1.0" date="2026-01-01T00:00:00"
          north="0" south="0" east="0" west="0" vendor="dualgrid tests"/>
{body}
</OpenDRIVE>
'''


def straight():
    xml, _ = road(1, 0.0, 0.0, 0.0, [("line", 600.0)])
    return document("straight", xml)


def curves():
    pieces = [("line", 150.0), ("spiral", 50.0, 0.0, 1 / 300), ("arc", 200.0, 1 / 300),
              ("spiral", 50.0, 1 / 300, 0.0), ("line", 150.0), ("arc", 150.0, -1 / 200),
              ("arc", 150.0, 1 / 200), ("line", 200.0)]
    xml, _ = road(1, 0.0, 0.0, 0.0, pieces)
    return document("curves", xml)


def junction():
    r, j = 10.0, 100  # junction half-size (connecting-road radius) [m] and id
    jl = f'<successor elementType="junction" elementId="{j}"/>'
    jp = f'<predecessor elementType="junction" elementId="{j}"/>'
    roads = [
        road(1, -r - 200.0, 0.0, 0.0, [("line", 200.0)], link=jl)[0],  # west arm, ends at the junction
        road(2, r, 0.0, 0.0, [("line", 60.0), ("arc", 100.0, 1 / 250), ("line", 40.0)],
             link=jp)[0],  # east arm, starts at the junction, bends left
        road(3, 0.0, -r, -math.pi / 2, [("line", 200.0)], link=jp)[0],  # south arm, from the junction
    ]
    quarter = math.pi / 2 * r

    def connecting(cid, x, y, hdg, pieces, pred, pred_cp, succ, succ_cp, from_lane, to_lane):
        link = (f'<predecessor elementType="road" elementId="{pred}" contactPoint="{pred_cp}"/>'
                f'<successor elementType="road" elementId="{succ}" contactPoint="{succ_cp}"/>')
        xml, _ = road(cid, x, y, hdg, pieces, junction=j, link=link, left=False,
                      lane_links={-1: (from_lane, to_lane)})
        return xml

    # (id, start, pieces, incoming road, its contact point, outgoing road, its contact point,
    #  incoming lane, outgoing lane)
    conns = [
        (10, (-r, 0.0, 0.0), [("line", 2 * r)], 1, "end", 2, "start", -1, -1),             # W -> E
        (11, (r, 0.0, math.pi), [("line", 2 * r)], 2, "start", 1, "end", 1, 1),            # E -> W
        (12, (-r, 0.0, 0.0), [("arc", quarter, -1 / r)], 1, "end", 3, "start", -1, -1),    # W -> S
        (13, (0.0, -r, math.pi / 2), [("arc", quarter, -1 / r)], 3, "start", 2, "start", 1, -1),  # S -> E
        (14, (r, 0.0, math.pi), [("arc", quarter, 1 / r)], 2, "start", 3, "start", 1, -1),  # E -> S
        (15, (0.0, -r, math.pi / 2), [("arc", quarter, 1 / r)], 3, "start", 1, "end", 1, 1),  # S -> W
    ]
    connections = []
    for n, (cid, (x, y, h), pieces, inc, inc_cp, out, out_cp, lf, lt) in enumerate(conns):
        roads.append(connecting(cid, x, y, h, pieces, inc, inc_cp, out, out_cp, lf, lt))
        connections.append(f'    <connection id="{n}" incomingRoad="{inc}" connectingRoad="{cid}" '
                           f'contactPoint="start"><laneLink from="{lf}" to="-1"/></connection>')
    body = "\n".join(roads) + f'\n  <junction id="{j}" name="T">\n' + "\n".join(connections) + \
        "\n  </junction>"
    return document("junction", body)


def broken():
    return document("broken", '''  <road name="no geometry" length="100" id="1" junction="-1">
    <link/>
    <planView/>
    <lanes><laneSection s="0"><center><lane id="0" type="none" level="false"/></center></laneSection></lanes>
  </road>''')


def main():
    kinds = {"straight": straight, "curves": curves, "junction": junction, "broken": broken}
    if len(sys.argv) != 3 or sys.argv[1] not in kinds:
        sys.exit(__doc__)
    with open(sys.argv[2], "w", encoding="utf-8") as f:
        f.write(kinds[sys.argv[1]]())


if __name__ == "__main__":
    main()
