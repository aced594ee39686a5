#!/usr/bin/env python3
"""Browser test of the interactive replay viewer (docs/replay.md, viz/viewer/viewer.html).

Usage: viewer_check.py DUALGRID_BINARY WORK_DIR   (run from the source tree: scenarios/ is read)

Records a short simple_road run, writes its viewer with `dualgrid replay RUN --html`, opens it in
headless Chromium driven over the DevTools protocol (--remote-debugging-pipe: NUL-terminated JSON
on fds 3 and 4, no websocket library) and works the page with real input events only: key
presses, clicks on the slider and the layer checkboxes, mouse moves. The page's read-only hook
(window.dualgridViewer) is used to wait for drawing and to find a cell's pixel, never to act.
Expected values come from index.json and frames.bin, decoded here with zlib.

Exit codes: 0 passed, 1 a check failed (one-line reason), 77 skipped (no chromium).
Python 3 standard library only.
"""
import base64
import fcntl
import json
import math
import os
import re
import select
import shutil
import signal
import struct
import subprocess
import sys
import tempfile
import time
import zlib

SKIP = 77
VIEWPORT = (2000, 1100)  # CSS px; device scale 1, so a screenshot pixel is a CSS pixel
EGO = (77, 199, 77)      # the ego's fill
TOLERANCE = 4            # per channel [0-255]: the cell centre is sampled, no antialiasing there


class Failure(Exception):
    pass


def ok(what):
    print(f"ok   {what}", flush=True)


def require(cond, what):
    if not cond:
        raise Failure(what)
    ok(what)


# --------------------------------------------------------------------------------------------
# The recording, read the way docs/replay.md describes it
# --------------------------------------------------------------------------------------------
def hue(vx, vy):
    """HueColor (viz/src/color.cpp): HSV, S = V = 1, hue = direction CCW from +x."""
    h = math.atan2(vy, vx)
    if h < 0:
        h += 2 * math.pi
    h = h / (2 * math.pi) * 6
    s = min(int(h), 5)
    f = h - s
    q = 1 - f
    return [(1, f, 0), (q, 1, 0), (0, 1, f), (0, q, 1), (f, 0, 1), (1, 0, q)][s]


def blend(f, s, d, vx, vy):
    """CellColor's blend (viz/src/grid_panels.cpp), masses in [0, 1], channels 0..255."""
    total = f + s + d
    if total > 1:
        f, s, d = f / total, s / total, d / total
    u = max(0.0, 1 - f - s - d)
    base = f + 0.5 * u
    return tuple(int(min(1.0, max(0.0, base + d * c)) * 255 + 0.5) for c in hue(vx, vy))


def load_frame(run, index, k):
    n = index["cells_x"] * index["cells_y"]
    offset, length = index["frames"][k]["blob"]
    with open(os.path.join(run, "replay", "frames.bin"), "rb") as fh:
        fh.seek(offset)
        raw = zlib.decompress(fh.read(length))
    modes, at = [], 0
    for _ in index["modes"]:
        vx = struct.unpack_from(f"<{n}h", raw, at)
        vy = struct.unpack_from(f"<{n}h", raw, at + 2 * n)
        modes.append({"vx": vx, "vy": vy})
        at += 4 * n
    for rec in index["frames"][k]["modes"]:  # particles: not checked here
        at += 4 * rec["np"]
    for m in modes:
        m["free"], m["static"], m["dynamic"] = raw[at:at + n], raw[at + n:at + 2 * n], raw[at + 2 * n:at + 3 * n]
        at += 3 * n
    if at != len(raw):
        raise Failure(f"frame {k}: {len(raw)} bytes inflated, the index implies {at}")
    return modes


def cell_colour(m, c, dynamic_on=True):
    d = m["dynamic"][c] / 255 if dynamic_on else 0.0
    return blend(m["free"][c] / 255, m["static"][c] / 255, d, m["vx"][c], m["vy"][c])


def pick_cell(run, index):
    """A frame (after a few steps) and a cell with dynamic mass >= 0.9, away from the ego, whose
    3x3 neighbours are as close to its colour as can be found (so that a pixel a little off the
    cell's centre would still read right)."""
    nx, ny, res = index["cells_x"], index["cells_y"], index["resolution"]
    frames = index["frames"]
    order = [m for m in ("dual", "velocity", "position") if m in index["modes"]]
    order += [m for m in index["modes"] if m not in order]
    best = None
    for k in range(3, min(len(frames), 60)):
        modes = load_frame(run, index, k)
        fr = frames[k]
        for name in order:
            mi = index["modes"].index(name)
            m = modes[mi]
            for c in range(nx * ny):
                i, j = c % nx, c // nx
                if m["dynamic"][c] < 230 or not (1 <= i < nx - 1 and 1 <= j < ny - 1):
                    continue
                x = fr["origin"][0] + (i + 0.5) * res - fr["ego"][1]
                y = fr["origin"][1] + (j + 0.5) * res - fr["ego"][2]
                if abs(x) < fr["ego"][4] and abs(y) < fr["ego"][4]:
                    continue
                colour = cell_colour(m, c)
                spread = max(max(abs(a - b) for a, b in zip(colour, cell_colour(m, (j + dj) * nx + i + di)))
                             for di in (-1, 0, 1) for dj in (-1, 0, 1))
                if best is None or spread < best[0]:
                    best = (spread, (k, mi, i, j, m))
        if best and best[0] <= 16:
            break
    if best is None:
        raise Failure("no frame in the first 6 s has a cell with dynamic mass >= 0.9 (recording changed?)")
    return best[1]


# --------------------------------------------------------------------------------------------
# PNG decoding (Page.captureScreenshot), pure Python
# --------------------------------------------------------------------------------------------
def decode_png(data):
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        raise Failure("screenshot is not a PNG")
    at, idat, width = 8, [], 0
    while at < len(data):
        length, kind = struct.unpack_from(">I4s", data, at)
        body = data[at + 8:at + 8 + length]
        at += 12 + length
        if kind == b"IHDR":
            width, height, depth, ctype, _, _, interlace = struct.unpack(">IIBBBBB", body)
            if depth != 8 or ctype not in (2, 6) or interlace:
                raise Failure(f"screenshot PNG: depth {depth}, colour type {ctype}, interlace {interlace} not handled")
            bpp = 3 if ctype == 2 else 4
        elif kind == b"IDAT":
            idat.append(body)
        elif kind == b"IEND":
            break
    raw = zlib.decompress(b"".join(idat))
    stride = width * bpp
    rows, prev, at = [], bytearray(stride), 0
    for _ in range(height):
        ftype, line = raw[at], bytearray(raw[at + 1:at + 1 + stride])
        at += 1 + stride
        for x in range(stride):
            a = line[x - bpp] if x >= bpp else 0
            b = prev[x]
            c = prev[x - bpp] if x >= bpp else 0
            if ftype == 1:
                line[x] = (line[x] + a) & 255
            elif ftype == 2:
                line[x] = (line[x] + b) & 255
            elif ftype == 3:
                line[x] = (line[x] + (a + b) // 2) & 255
            elif ftype == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[x] = (line[x] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
            elif ftype != 0:
                raise Failure(f"screenshot PNG: filter type {ftype}")
        rows.append(line)
        prev = line
    return lambda x, y: tuple(rows[y][x * bpp:x * bpp + 3])


# --------------------------------------------------------------------------------------------
# Chromium over --remote-debugging-pipe
# --------------------------------------------------------------------------------------------
class Browser:
    def __init__(self, chromium, profile, log):
        # The pipe ends go to fds 3 (commands in) and 4 (replies out) of Chromium. Every descriptor
        # handed over is first moved to 10 or above: one that happened to be 3 or 4 itself would be
        # overwritten by the other's dup2 (ctest leaves 3 and 4 free, so the log file got one).
        def high(fd):
            moved = fcntl.fcntl(fd, fcntl.F_DUPFD_CLOEXEC, 10)
            os.close(fd)
            return moved
        cmd_r, cmd_w = map(high, os.pipe())
        out_r, out_w = map(high, os.pipe())
        log_fd = high(os.open(log, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o644))
        args = [chromium, "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic",
                "--no-first-run", "--disable-background-networking", "--disable-component-update",
                "--disable-sync", f"--user-data-dir={profile}", "--remote-debugging-pipe",
                f"--window-size={VIEWPORT[0]},{VIEWPORT[1]}", "--hide-scrollbars", "about:blank"]
        actions = [(os.POSIX_SPAWN_DUP2, log_fd, 1), (os.POSIX_SPAWN_DUP2, log_fd, 2),
                   (os.POSIX_SPAWN_DUP2, cmd_r, 3), (os.POSIX_SPAWN_DUP2, out_w, 4)]
        # Its own session, so that the browser and every helper process it starts end together.
        self.pid = os.posix_spawn(chromium, args, os.environ, file_actions=actions, setsid=True)
        for fd in (cmd_r, out_w, log_fd):
            os.close(fd)
        self.w, self.r = cmd_w, out_r
        self.buf, self.next_id, self.session = b"", 0, None

    def close(self):
        try:
            os.killpg(self.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
        try:
            os.waitpid(self.pid, 0)
        except ChildProcessError:
            pass
        for fd in (self.w, self.r):
            try:
                os.close(fd)
            except OSError:
                pass

    def _message(self, deadline):
        while b"\0" not in self.buf:
            left = deadline - time.monotonic()
            if left <= 0 or not select.select([self.r], [], [], left)[0]:
                raise Failure("no reply from Chromium within the timeout")
            chunk = os.read(self.r, 1 << 20)
            if not chunk:
                raise Failure("Chromium closed the DevTools pipe (crashed? see chromium.log)")
            self.buf += chunk
        msg, self.buf = self.buf.split(b"\0", 1)
        return json.loads(msg)

    def call(self, method, params=None, timeout=30, session=True):
        self.next_id += 1
        msg = {"id": self.next_id, "method": method, "params": params or {}}
        if session and self.session:
            msg["sessionId"] = self.session
        os.write(self.w, json.dumps(msg).encode() + b"\0")
        deadline = time.monotonic() + timeout
        while True:
            reply = self._message(deadline)
            if reply.get("id") == self.next_id:
                if "error" in reply:
                    raise Failure(f"{method}: {reply['error'].get('message')}")
                return reply.get("result", {})

    def open(self, url):
        target = self.call("Target.createTarget", {"url": "about:blank"}, session=False)["targetId"]
        self.session = self.call("Target.attachToTarget", {"targetId": target, "flatten": True},
                                 session=False)["sessionId"]
        for method in ("Page.enable", "Runtime.enable"):
            self.call(method)
        self.call("Emulation.setDeviceMetricsOverride",
                  {"width": VIEWPORT[0], "height": VIEWPORT[1], "deviceScaleFactor": 1, "mobile": False})
        self.call("Emulation.setFocusEmulationEnabled", {"enabled": True})
        self.call("Page.navigate", {"url": url})

    def eval(self, expression, timeout=30):
        r = self.call("Runtime.evaluate", {"expression": expression, "awaitPromise": True,
                                           "returnByValue": True, "timeout": timeout * 1000},
                      timeout=timeout + 5)
        if "exceptionDetails" in r:
            d = r["exceptionDetails"]
            text = d.get("exception", {}).get("description") or d.get("text") or "?"
            raise Failure(f"page error in `{expression[:60]}`: {text.splitlines()[0]}")
        return r["result"].get("value")

    def key(self, key, vk, code=None, text=None):
        """A key press and release (vk: Windows virtual key code, which Chromium maps)."""
        code = code or key
        down = {"type": "keyDown", "key": key, "code": code, "windowsVirtualKeyCode": vk}
        if text:
            down["text"] = text
        self.call("Input.dispatchKeyEvent", down)
        self.call("Input.dispatchKeyEvent", {"type": "keyUp", "key": key, "code": code, "windowsVirtualKeyCode": vk})

    def move(self, x, y):
        self.call("Input.dispatchMouseEvent", {"type": "mouseMoved", "x": x, "y": y})

    def click(self, x, y):
        self.move(x, y)
        for kind in ("mousePressed", "mouseReleased"):
            self.call("Input.dispatchMouseEvent", {"type": kind, "x": x, "y": y, "button": "left", "clickCount": 1})

    def screenshot(self, clip=None, save=None):
        """The viewport, or the page area clip = (x, y, w, h) [CSS px]: a pixel getter."""
        params = {"format": "png"}
        if clip:
            params["clip"] = dict(zip(("x", "y", "width", "height"), clip), scale=1)
        data = base64.b64decode(self.call("Page.captureScreenshot", params)["data"])
        if save:
            with open(save, "wb") as fh:
                fh.write(data)
        return decode_png(data)


# --------------------------------------------------------------------------------------------
# The checks
# --------------------------------------------------------------------------------------------
def wait_until(browser, expression, what, timeout=20):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        try:
            value = browser.eval(expression, timeout=10)
        except Failure:
            value = None
        if value:
            return value
        time.sleep(0.1)
    raise Failure(f"timed out after {timeout} s waiting for {what}")


def drawn(browser):
    return browser.eval("window.dualgridViewer.drawn()")


def shown_time(browser):
    text = browser.eval("document.getElementById('time').textContent")
    m = re.search(r"t = (-?\d+\.\d+) s", text or "")
    if not m:
        raise Failure(f"time stamp text {text!r} is not 't = <seconds> s'")
    return float(m.group(1))


def centre_of(browser, selector):
    r = browser.eval(f"(() => {{ const r = document.querySelector({json.dumps(selector)}).getBoundingClientRect();"
                     f" return [r.left + r.width / 2, r.top + r.height / 2, r.left, r.width]; }})()")
    if not r:
        raise Failure(f"no element {selector}")
    return r


def toggle(browser, selector, want):
    x, y, _, _ = centre_of(browser, selector)
    browser.click(x, y)
    state = browser.eval(f"document.querySelector({json.dumps(selector)}).checked")
    require(state == want, f"click on {selector} -> checked = {want}")
    drawn(browser)


def cell_page(browser, mode, i, j):
    """Page CSS pixel (integer) of the centre of cell (i, j), inside the viewport."""
    p = browser.eval(f"window.dualgridViewer.cellToPage({mode}, {i}, {j})")
    if not p:
        raise Failure(f"cellToPage({mode}, {i}, {j}) returned nothing: panel not shown")
    sx, sy = browser.eval("[window.scrollX, window.scrollY]")
    x, y = int(p["x"]), int(p["y"])
    if not (0 <= x - sx < VIEWPORT[0] and 0 <= y - sy < VIEWPORT[1]):
        raise Failure(f"cell ({i}, {j}) lies at ({x}, {y}), outside the {VIEWPORT} viewport")
    return x, y


def pixel(browser, x, y):
    """Colour of page pixel (x, y): the centre of a 5 x 5 px screenshot around it (a whole
    viewport takes a second or two to unfilter in Python)."""
    return browser.screenshot(clip=(x - 2, y - 2, 5, 5))(2, 2)


def close(a, b, tol=TOLERANCE):
    return max(abs(p - q) for p, q in zip(a, b)) <= tol


def check_load_and_layout(browser, index, html):
    frames = index["frames"]
    browser.open("file://" + os.path.abspath(html))
    wait_until(browser, "location.protocol === 'file:' && document.readyState === 'complete'"
                        " && !!window.dualgridViewer", "the page to load")
    browser.eval("window.dualgridViewer.ready")
    require(browser.eval("window.dualgridViewer.frameCount()") == len(frames), f"page holds all {len(frames)} frames")
    require(abs(shown_time(browser) - frames[0]["t"]) < 0.005, f"first frame shown, t = {frames[0]['t']}")
    # All modes shown; stacked when the grid is more than 2.5 times as wide as high.
    corners = [browser.eval(f"window.dualgridViewer.cellToPage({i}, 0, 0)") for i in range(len(index["modes"]))]
    stacked = index["cells_x"] > 2.5 * index["cells_y"]
    along, across = ("x", "y") if stacked else ("y", "x")
    require(all(corners) and all(abs(a[along] - b[along]) < 1 and b[across] > a[across]
                                 for a, b in zip(corners, corners[1:])),
            f"{len(corners)} panels {'stacked' if stacked else 'side by side'} for a "
            f"{index['cells_x']} x {index['cells_y']} grid")


def check_stepping(browser, frames, k):
    """ArrowRight k times: one frame per press, the time text and the slider follow."""
    for _ in range(k):
        browser.key("ArrowRight", 39)
    drawn(browser)
    t = shown_time(browser)
    require(abs(t - frames[k]["t"]) < 0.005, f"ArrowRight x{k}: time text {t} == frames[{k}].t = {frames[k]['t']}")
    slider = int(browser.eval("document.getElementById('slider').value"))
    require(slider == k, f"slider moved to {slider} == {k}")
    browser.key("ArrowLeft", 37)
    browser.key("ArrowRight", 39)
    require(browser.eval("window.dualgridViewer.frame()") == k, "ArrowLeft then ArrowRight: back at the same frame")
    drawn(browser)


def check_pixels(browser, index, html, k, mi, ci, cj, m):
    """The cell's pixel has its blend colour; with the dynamic layer off, its unknown grey."""
    # Overlays off (truth, clusters, detections), so that the cell's pixel is the cell's colour.
    toggle(browser, "#layer-truth", False)
    toggle(browser, "#layer-clusters", False)
    for s in range(len(index.get("sensors", []))):
        toggle(browser, f"#layer-sensor-{s}", False)

    # One whole-viewport screenshot (kept for a look): the ego box is filled green.
    fr = index["frames"][k]
    ei = int((fr["ego"][1] - fr["origin"][0]) // index["resolution"])
    ej = int((fr["ego"][2] - fr["origin"][1]) // index["resolution"])
    ex, ey = cell_page(browser, mi, ei, ej)
    sx, sy = browser.eval("[window.scrollX, window.scrollY]")
    got = browser.screenshot(save=os.path.join(os.path.dirname(html), "viewer_check.png"))(ex - sx, ey - sy)
    require(close(got, EGO), f"ego centre pixel ({ex}, {ey}) = {got}, ego green {EGO}")

    x, y = cell_page(browser, mi, ci, cj)
    x1, _ = cell_page(browser, mi, ci + 1, cj)
    require(x1 - x >= 3, f"a cell is {x1 - x} px wide on the page (>= 3 px: its centre pixel is its own)")
    c = cj * index["cells_x"] + ci
    expected = cell_colour(m, c)
    got = pixel(browser, x, y)
    require(close(got, expected), f"pixel ({x}, {y}) of cell ({ci}, {cj}) = {got}, expected {expected} (±{TOLERANCE})")

    # The dynamic layer off: its mass reads as unknown.
    toggle(browser, "#layer-dynamic", False)
    got_off = pixel(browser, x, y)
    expected_off = cell_colour(m, c, dynamic_on=False)
    require(close(got_off, expected_off) and not close(got_off, expected, 60),
            f"dynamic layer off: pixel = {got_off}, expected {expected_off} (grey), not the hue {expected}")
    toggle(browser, "#layer-dynamic", True)
    require(close(pixel(browser, x, y), expected), "dynamic layer on again: the hue is back")
    return x, y


def check_hover(browser, index, x, y, ci, cj, m):
    """Hover read-out: the recorded masses and velocity of the cell under the cursor."""
    c = cj * index["cells_x"] + ci
    browser.move(x, y)
    text = wait_until(browser, "(() => { const t = document.getElementById('readout').textContent;"
                               " return t.includes('free') ? t : ''; })()", "the hover read-out")
    cell = re.search(r"cell \((\d+), (\d+)\)", text)
    masses = re.search(r"free (\d\.\d\d)\s+static (\d\.\d\d)\s+dynamic (\d\.\d\d)\s+unknown (\d\.\d\d)", text)
    if not cell or not masses:
        raise Failure(f"hover read-out lacks the cell or masses: {text!r}")
    require((int(cell.group(1)), int(cell.group(2))) == (ci, cj), f"hover names cell ({ci}, {cj}): {cell.group(0)}")
    want = [m["free"][c] / 255, m["static"][c] / 255, m["dynamic"][c] / 255]
    want.append(max(0.0, 1 - sum(want)))
    shown = [float(g) for g in masses.groups()]
    require(all(abs(a - b) <= 0.01 for a, b in zip(shown, want)),
            f"hover masses {shown} == recorded {[round(w, 3) for w in want]} (±0.01)")
    speed = re.search(r"speed (\d+\.\d\d) m/s", text)
    want_speed = (m["vx"][c] ** 2 + m["vy"][c] ** 2) ** 0.5 / 100
    require(speed and abs(float(speed.group(1)) - want_speed) <= 0.01,
            f"hover speed {speed and speed.group(1)} == recorded {want_speed:.2f} m/s")


def check_slider_and_keys(browser, frames):
    """A click on the slider's track jumps there; with the slider focused an arrow still steps
    once (not page + slider); Home and End."""
    _, y, left, width = centre_of(browser, "#slider")
    browser.click(left + 0.75 * width, y)
    drawn(browser)
    f = browser.eval("window.dualgridViewer.frame()")
    slider = int(browser.eval("document.getElementById('slider').value"))
    t = shown_time(browser)
    require(f == slider and abs(f - 0.75 * (len(frames) - 1)) <= 0.1 * len(frames) + 1
            and abs(t - frames[f]["t"]) < 0.005,
            f"click at 75 % of the slider: frame {f} of {len(frames)}, time text {t} == {frames[f]['t']}")
    browser.key("ArrowRight", 39)
    f1 = browser.eval("window.dualgridViewer.frame()")
    require(f1 == min(f + 1, len(frames) - 1), f"ArrowRight on the focused slider: frame {f} -> {f1}")
    browser.key("End", 35)
    require(abs(shown_time(browser) - frames[-1]["t"]) < 0.005, f"End: last frame, t = {frames[-1]['t']}")
    browser.key("Home", 36)
    require(abs(shown_time(browser) - frames[0]["t"]) < 0.005, f"Home: first frame, t = {frames[0]['t']}")


def check_ghost_layer(browser, index):
    """Multipath ghosts (docs/replay.md): their own layer. At a frame with ghosts, with only their
    radar's detections shown, switching the layer off changes pixels on the ghosts' rings (drawn
    2.5 px around each ghost) and switching it on again brings every one of them back."""
    has = browser.eval("!!document.getElementById('layer-ghosts')")
    if not index.get("multipath"):
        require(not has, "no ghost layer without multipath")
        return
    require(has, "a 'multipath ghosts' layer when the recording has multipath")
    frames = index["frames"]
    k = next((i for i, f in enumerate(frames) if any(len(d) > 6 for d in f["det"])), None)
    require(k is not None, "the multipath recording has ghosts")
    browser.key("Home", 36)
    for _ in range(k):
        browser.key("ArrowRight", 39)
    drawn(browser)
    require(browser.eval("window.dualgridViewer.frame()") == k, f"at frame {k}, which has ghosts")
    fr, res = frames[k], index["resolution"]
    sensors = sorted({d[0] for d in fr["det"] if len(d) > 6})
    for s in range(len(index.get("sensors", []))):
        selector = f"#layer-sensor-{s}"
        if browser.eval(f"document.querySelector({json.dumps(selector)}).checked") != (s in sensors):
            toggle(browser, selector, s in sensors)
    mode = browser.eval("window.dualgridViewer.panels()")[0]
    sx, sy = browser.eval("[window.scrollX, window.scrollY]")
    points = []  # ring pixels of every ghost inside the viewport
    for d in fr["det"]:
        if len(d) <= 6:
            continue
        ci, cj = int((d[1] - fr["origin"][0]) // res), int((d[2] - fr["origin"][1]) // res)
        p0 = browser.eval(f"window.dualgridViewer.cellToPage({mode}, {ci}, {cj})")
        p1 = browser.eval(f"window.dualgridViewer.cellToPage({mode}, {ci + 1}, {cj + 1})")
        if not p0 or not p1:
            continue
        # The cell centres' pixels give the map's scale (y up on the page's y down).
        kx, ky = (p1["x"] - p0["x"]) / res, (p1["y"] - p0["y"]) / res
        x = p0["x"] + (d[1] - fr["origin"][0] - (ci + 0.5) * res) * kx
        y = p0["y"] + (d[2] - fr["origin"][1] - (cj + 0.5) * res) * ky
        for a in range(8):
            px = int(round(x + 2.5 * math.cos(a * math.pi / 4))) - sx
            py = int(round(y + 2.5 * math.sin(a * math.pi / 4))) - sy
            if 0 <= px < VIEWPORT[0] and 0 <= py < VIEWPORT[1]:
                points.append((px, py))
    require(points, "ghost rings inside the viewport")
    on = browser.screenshot()
    before = [on(x, y) for x, y in points]
    toggle(browser, "#layer-ghosts", False)
    off = browser.screenshot()
    changed = sum(1 for (x, y), b in zip(points, before) if not close(off(x, y), b, 3))
    require(changed > 0, f"ghost layer off: {changed} of {len(points)} ring pixels changed")
    toggle(browser, "#layer-ghosts", True)
    again = browser.screenshot()
    require(all(close(again(x, y), b, 3) for (x, y), b in zip(points, before)),
            "ghost layer on again: every ring pixel is back")
    print(f"ghost layer: {changed} of {len(points)} ring pixels at frame {k} change", flush=True)


def check_playback(browser, index):
    """Space plays in real time, Space again pauses. The focus is on a checkbox clicked just
    before: Space must not toggle it."""
    toggle(browser, "#layer-particles", True)
    t0 = shown_time(browser)
    start = time.monotonic()
    browser.key(" ", 32, code="Space", text=" ")
    wait_until(browser, "window.dualgridViewer.playing()", "playback to start", timeout=5)
    time.sleep(1.5)
    browser.key(" ", 32, code="Space", text=" ")
    elapsed = time.monotonic() - start
    require(not browser.eval("window.dualgridViewer.playing()"), "Space again: paused")
    t1 = shown_time(browser)
    require(0.5 <= t1 - t0 <= elapsed + 2 * index["interval"] + 0.05,
            f"played {t1 - t0:.2f} s of recording in {elapsed:.2f} s of real time (1x)")
    require(browser.eval("document.getElementById('layer-particles').checked") is True,
            "Space did not toggle the focused checkbox")
    time.sleep(0.4)
    require(abs(shown_time(browser) - t1) < 1e-9, "paused: the time stays")


def run_checks(browser, index, run, html):
    k, mi, ci, cj, m = pick_cell(run, index)
    c = cj * index["cells_x"] + ci
    print(f"cell ({ci}, {cj}) of mode {index['modes'][mi]} at frame {k} (t = {index['frames'][k]['t']} s): "
          f"free {m['free'][c]}, static {m['static'][c]}, dynamic {m['dynamic'][c]} /255, "
          f"v = ({m['vx'][c]}, {m['vy'][c]}) cm/s", flush=True)
    check_load_and_layout(browser, index, html)
    check_stepping(browser, index["frames"], k)
    x, y = check_pixels(browser, index, html, k, mi, ci, cj, m)
    check_hover(browser, index, x, y, ci, cj, m)
    check_slider_and_keys(browser, index["frames"])
    check_ghost_layer(browser, index)
    check_playback(browser, index)


def record(binary, work):
    """A 6 s simple_road run with multipath ghosts (its rails and trucks are mirrors) and its
    recording (figures on: they switch the recording on; PNG only, for speed) and its viewer
    page. Returns (run folder, page)."""
    run, html = os.path.join(work, "run"), os.path.join(work, "replay.html")
    for cmd in ([binary, "run", "scenarios/simple_road.yaml", "--out", run, "--duration", "6",
                 "--figure-formats", "png", "--set", "sensors.multipath=on", "--record-interval", "0.1",
                 "--quiet"],
                [binary, "replay", run, "--html", "--html-out", html, "--quiet"]):
        print("$", " ".join(cmd), flush=True)
        try:
            done = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, timeout=200)
        except subprocess.TimeoutExpired:
            raise Failure(f"`{' '.join(cmd[:2])}` took more than 200 s")
        if done.returncode != 0:
            print(done.stdout)
            raise Failure(f"`{' '.join(cmd[:2])}` exited with {done.returncode}")
    return run, html


def main():
    if len(sys.argv) != 3:
        print(__doc__)
        return 2
    binary, work = sys.argv[1], sys.argv[2]
    chromium = shutil.which("chromium")
    if not chromium:
        print("SKIP: chromium not found on PATH (Debian: apt-get install chromium)")
        return SKIP
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    browser = None
    try:
        run, html = record(binary, work)
        with open(os.path.join(run, "replay", "index.json")) as fh:
            index = json.load(fh)
        profile = tempfile.mkdtemp(prefix="chromium_profile_", dir=work)
        browser = Browser(chromium, profile, os.path.join(work, "chromium.log"))
        run_checks(browser, index, run, html)
    except Failure as e:
        print(f"FAIL: {e}")
        return 1
    finally:
        if browser:
            browser.close()
    print("viewer_check: all checks passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
