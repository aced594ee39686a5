#!/usr/bin/env python3
"""The tables of docs/results.md sections 1, 2, 3 and 9, and a comparison of two measurements.

Usage: scripts/results_tables.py tables OUT [--section 1|2|3|9]
       scripts/results_tables.py compare OLD NEW [--moved] [--metrics D_v,delta_v,...]

OUT is a folder written by scripts/ablation.sh (its stages switches, dualgrid, paper and fit):
OUT/SCENARIO/EXPERIMENT/{table.csv,summary.json}. An experiment whose summary.json does not say
"complete": true is left out (one line on stderr names it), so a run that did not finish never
looks finished. `fit_none` and `fit_both` fall back to `bdoppler_zkeep_lradial` and
`preset_dualgrid` when missing (the same settings: the dualgrid preset with Doppler births and the
radial likelihood, and the dualgrid preset itself).

`tables` prints, per section, a comment line `<!-- section N -->` and the Markdown tables of the
section in the page's formats, each preceded by the line that introduces it on the page (a label
or a heading); section 9 ends with scripts/ablation.sh's own table of the fit_* experiments.

`compare` reads OLD and NEW, each an OUT folder or a Markdown page in the format of
docs/results.md (the tables of its sections 1, 2, 3 and 9 are parsed; a value quoted twice is
taken where it has the most decimals; each value is compared at the coarser of its two
precisions), and prints (Markdown) two tables:
  1. every (scenario, experiment, metric, mode) of both: old and new mean ± 95 % CI half-width,
     the difference, and "moved" when |new - old| exceeds the larger of the two half-widths;
  2. every pair of modes (per scenario, experiment and metric) whose relation changed: "a > b"
     (a better: higher D, D_v, F1, lower otherwise), "a >> b" when the intervals do not overlap
     (|a - b| > ci_a + ci_b); the change is "flipped, intervals apart" (the order turned and the
     intervals were or are apart), "reordered within intervals", "now apart" or "now within
     intervals". Two modes equal at the printed precision are a tie, not an order.
--moved lists only the moved rows of table 1; --metrics restricts both tables.

Exit status: 0 done; 2 bad input (a missing folder or page, an unreadable table: one line naming
the file and what was expected). Standard library only.
"""
import csv
import io
import json
import math
import os
import re
import signal
import sys

MODES = ["position", "velocity", "dual"]
ABBREV = {"pos": "position", "vel": "velocity", "dua": "dual", "dual": "dual"}
SCENARIOS = ["simple_road", "highway", "crossing", "parallel"]
# Scenario names as the page writes them: section 2's labels and section 3's headings.
SCENARIO_TITLE = {"simple_road": "Simple road", "highway": "Highway",
                  "crossing": "Crossing traffic", "parallel": "Parallel traffic"}
SECTION2_LABEL = {
    "simple_road": "Simple road (beside Table I):",
    "highway": "Highway (beside Table II):",
    "crossing": "Crossing traffic (4 cars crossing ahead at 15 m/s, perpendicular to the front "
                "radar):",
    "parallel": "Parallel traffic (alongside, perpendicular to the corner radars):",
}
# Section 3's rows: experiment folder -> the row's label on the page, in the page's order.
SECTION3_ROWS = [
    ("preset_dualgrid", "Doppler-fit births, keep split, radial_fit (**dualgrid**, section 9)"),
    ("bdoppler_zkeep_lvector", "Doppler births, keep split, vector"),
    ("bdoppler_zkeep_lradial", "Doppler births, keep split, radial (**dualgrid** before issue 28)"),
    ("bdoppler_zliteral_lvector", "Doppler births, literal eq. 7, vector"),
    ("bdoppler_zliteral_lradial", "Doppler births, literal eq. 7, radial"),
    ("buniform_zkeep_lvector", "uniform births, keep split, vector"),
    ("buniform_zkeep_lradial", "uniform births, keep split, radial"),
    ("buniform_zliteral_lvector", "uniform births, literal eq. 7, vector"),
    ("buniform_zliteral_lradial", "uniform births, literal eq. 7, radial"),
    ("preset_paper", "**paper** (uniform, literal eq. 7, vector, literal eqs. 9-12)"),
    ("preset_paper_bdoppler", "paper, but Doppler births"),
    ("preset_paper_lradial", "paper, but radial likelihood"),
]
FIT = ["fit_none", "fit_births", "fit_likelihood", "fit_both"]
FALLBACK = {"fit_none": "bdoppler_zkeep_lradial", "fit_both": "preset_dualgrid"}
# Section 9's summary rows: (scenario, experiment); fit_none is labelled "(earlier default)".
SECTION9_ROWS = [("crossing", e) for e in FIT] + [
    (s, e) for s in ("simple_road", "highway", "parallel") for e in ("fit_none", "fit_both")]
# Rows of the per-metric tables (sections 1 and 2): metric -> (label, decimals).
METRIC_ROWS = {
    "delta_x": ("Δx [m]", 2), "delta_v": ("Δv [m/s]", 2), "t_d": ("t_d [s]", 2),
    "D": ("D [%]", 1), "D_v": ("D_v (velocity right) [%]", 1),
    "box_distance": ("Δx to box surface [m]", 2),
    "false_clusters_per_scan": ("false clusters / scan", 2),
    "objects_never_tracked": ("objects never tracked", 1),
    "dynamic_cell_f1": ("dynamic-cell F1", 3),
}
PAPER_ROWS = ["delta_x", "delta_v", "t_d", "D", "D_v"]
STRESS_ROWS = ["delta_x", "delta_v", "t_d", "D", "D_v", "box_distance",
               "false_clusters_per_scan", "objects_never_tracked", "dynamic_cell_f1"]
# Column names of the ablation tables (sections 3 and 9) -> metric.
COLUMN_METRIC = {"D_v %": "D_v", "D %": "D", "D_v": "D_v", "D": "D", "Δv": "delta_v",
                 "Δx": "delta_x", "delta_v": "delta_v", "delta_x": "delta_x", "t_d": "t_d"}
HIGHER_IS_BETTER = {"D", "D_v", "dynamic_cell_f1"}


def fail(message):
    print(f"results_tables.py: {message}", file=sys.stderr)
    sys.exit(2)


def printable(text):
    """TEXT with control characters escaped (an error line stays one line of text)."""
    return "".join(c if c.isprintable() else c.encode("unicode_escape").decode("ascii")
                   for c in text)


def read_text(path):
    """The UTF-8 text of the regular file PATH; exits 2 naming it otherwise (a FIFO or a device is
    never opened: reading one could block or never end)."""
    if not os.path.isfile(path):
        fail(f"{path}: expected a regular file")
    try:
        with open(path, encoding="utf-8") as f:
            return f.read()
    except OSError as e:
        fail(f"{path}: cannot read ({e.strerror})")
    except UnicodeDecodeError:
        fail(f"{path}: expected UTF-8 text")


# ---------------------------------------------------------------------------------------------
# Reading an OUT folder: values {(scenario, experiment, metric, mode): (mean|None, ci|None,
# decimals)}, paper {(scenario, metric, mode): the paper's value}, seeds {(scenario, experiment):
# the number of seeds}.


def read_experiment(folder):
    """The rows of FOLDER/table.csv, or None (with a note) when the experiment did not finish."""
    summary = os.path.join(folder, "summary.json")
    complete = False
    if os.path.isfile(summary):  # a FIFO or a device is not opened: not complete
        try:
            with open(summary, encoding="utf-8") as f:
                data = json.load(f)
            complete = isinstance(data, dict) and data.get("complete") is True
        except (OSError, ValueError):  # UnicodeDecodeError is a ValueError
            complete = False
    if not complete:
        print(f"results_tables.py: {folder}: not complete (summary.json), left out",
              file=sys.stderr)
        return None
    path = os.path.join(folder, "table.csv")
    try:
        rows = list(csv.DictReader(io.StringIO(read_text(path), newline="")))
    except csv.Error as e:
        fail(f"{path}: expected CSV ({e})")
    need = {"metric", "mode", "n", "mean", "ci95_half_width", "paper"}
    if not rows or not need <= set(rows[0]):
        fail(f"{path}: expected a header with {', '.join(sorted(need))}")
    return rows


def number(text, path, key):
    if text is None:  # csv.DictReader's value for a row shorter than the header
        fail(f"{path}: {key}: missing (a row shorter than the header)")
    if text == "":
        return None
    try:
        value = float(text)
    except ValueError:
        fail(f"{path}: {key}: expected a number, got '{printable(text)}'")
    if not math.isfinite(value):
        fail(f"{path}: {key}: expected a finite number, got '{printable(text)}'")
    return value


def load_out(out):
    values, paper, seeds = {}, {}, {}
    for scen in SCENARIOS:
        base = os.path.join(out, scen)
        if not os.path.isdir(base):
            continue
        for exp in sorted(os.listdir(base)):
            folder = os.path.join(base, exp)
            rows = read_experiment(folder) if os.path.isdir(folder) else None
            if rows is None:
                continue
            path = os.path.join(folder, "table.csv")
            for r in rows:
                if not r["metric"] or not r["mode"]:
                    fail(f"{path}: expected a metric and a mode on every row")
                key = (scen, exp, r["metric"], r["mode"])
                values[key] = (number(r["mean"], path, "mean"),
                               number(r["ci95_half_width"], path, "ci95_half_width"), 6)
                p = number(r["paper"], path, "paper")
                if p is not None:
                    paper[(scen, r["metric"], r["mode"])] = p
            counts = [number(r["n"], path, "n") or 0 for r in rows]
            if any(c != int(c) or c < 0 for c in counts):
                fail(f"{path}: n: expected a whole number of seeds")
            seeds[(scen, exp)] = int(max(counts))
    for (scen, exp, metric, mode), v in list(values.items()):
        for alias, same in FALLBACK.items():
            if exp == same and (scen, alias, metric, mode) not in values:
                values[(scen, alias, metric, mode)] = v
    if not values:
        fail(f"{out}: expected experiment folders SCENARIO/EXPERIMENT/table.csv of "
             "scripts/ablation.sh")
    return values, paper, seeds


# ---------------------------------------------------------------------------------------------
# Formatting.


def cell(values, key, decimals):
    mean, ci, _ = values.get(key, (None, None, 0))
    if mean is None:
        return "—"
    return f"{mean:.{decimals}f}" + ("" if ci is None else f" ± {ci:.{decimals}f}")


def dual_gain(values, scen, exp):
    """Dual's D_v minus the better single weight's, '%+.1f', or '—'."""
    m = [values.get((scen, exp, "D_v", mode), (None,))[0] for mode in MODES]
    if None in m:
        return "—"
    return f"{m[2] - max(m[0], m[1]):+.1f}"


def paper_cell(paper, scen, metric, mode):
    p = paper.get((scen, metric, mode))
    if p is None:
        return "—"
    return f"{p:.0f}" if metric in ("D", "D_v") else f"{p:.2f}"


def metric_table(values, paper, scen, exp, with_paper):
    """Sections 1 and 2: one row per metric, the paper's values beside ours when with_paper."""
    if with_paper:
        head = ("| metric | position | position (paper) | velocity | velocity (paper) | dual "
                "| dual (paper) |")
    else:
        head = "| metric | position | velocity | dual |"
    lines = [head, "|---|" + "---:|" * (6 if with_paper else 3)]
    for metric in PAPER_ROWS if with_paper else STRESS_ROWS:
        label, dec = METRIC_ROWS[metric]
        if metric == "D_v" and not with_paper:
            label = "D_v [%]"
        cells = []
        for mode in MODES:
            cells.append(cell(values, (scen, exp, metric, mode), dec))
            if with_paper:
                cells.append(paper_cell(paper, scen, metric, mode))
        lines.append(f"| {label} | " + " | ".join(cells) + " |")
    return lines


def has(values, scen, exp):
    return any(k[0] == scen and k[1] == exp for k in values)


def section1(values, paper, seeds):
    out = []
    if has(values, "simple_road", "preset_paper"):
        out += [f"Simple road ({seeds.get(('simple_road', 'preset_paper'), 0)} seeds):", ""]
        out += metric_table(values, paper, "simple_road", "preset_paper", True) + [""]
    many = sorted(e for (s, e) in seeds
                  if s == "highway" and re.fullmatch(r"preset_paper_\d+seeds", e))
    for exp in many:
        out += [f"Highway (**{seeds[('highway', exp)]} seeds**):", ""]
        out += metric_table(values, paper, "highway", exp, True) + [""]
    return out


def section2(values, paper, seeds):
    out = []
    for scen in SCENARIOS:
        if has(values, scen, "preset_dualgrid"):
            out += [SECTION2_LABEL[scen], ""]
            out += metric_table(values, paper, scen, "preset_dualgrid",
                                scen in ("simple_road", "highway")) + [""]
    return out


def ablation_rows(values, scen, rows, groups, decimals, label_of, gain):
    """Rows of an ablation table: per experiment, per metric group, the three modes."""
    lines = []
    for exp in rows:
        if not has(values, scen, exp):
            continue
        cells = [cell(values, (scen, exp, m, mode), decimals) for m in groups for mode in MODES]
        if gain:
            cells.append(dual_gain(values, scen, exp))
        lines.append(f"| {label_of(exp)} | " + " | ".join(cells) + " |")
    return lines


def section3(values, paper, seeds):
    label = dict(SECTION3_ROWS)
    rows = [e for e, _ in SECTION3_ROWS]
    out = []
    for scen in SCENARIOS:
        if not any(has(values, scen, e) for e in rows):
            continue
        out += [f"### {SCENARIO_TITLE[scen]}",
                "| setting | D_v % pos | D_v % vel | D_v % dua | D % pos | D % vel | D % dua "
                "| dual − best single D_v |", "|---|" + "---:|" * 7]
        out += ablation_rows(values, scen, rows, ["D_v", "D"], 1, label.get, True) + [""]
        out += ["| setting | Δv pos | Δv vel | Δv dua | Δx pos | Δx vel | Δx dua | t_d pos "
                "| t_d vel | t_d dua |", "|---|" + "---:|" * 9]
        out += ablation_rows(values, scen, rows, ["delta_v", "delta_x", "t_d"], 2, label.get,
                             False) + [""]
    return out


def section9_summary(values):
    out = ["| scenario | setting | D_v % pos | D_v % vel | D_v % dual | dual − best single |",
           "|---|---|---:|---:|---:|---:|"]
    for scen, exp in SECTION9_ROWS:
        if not has(values, scen, exp):
            continue
        name = exp + (" (earlier default)" if exp == "fit_none" else "")
        cells = [cell(values, (scen, exp, "D_v", mode), 1) for mode in MODES]
        out.append(f"| {scen.replace('_', ' ')} | {name} | " + " | ".join(cells)
                   + f" | {dual_gain(values, scen, exp)} |")
    return out + [""]


def section9_all(values):
    """scripts/ablation.sh's own table format, the fit_* experiments only."""
    out = []
    for scen in SCENARIOS:
        exps = sorted(e for e in FIT if has(values, scen, e))
        if not exps:
            continue
        for groups in (["D_v", "D"], ["delta_v", "delta_x", "t_d"]):
            head = "| configuration |" + "".join(
                f" {m} {mode[:3]} |" for m in groups for mode in MODES)
            gain = groups[0] == "D_v"
            head += " dual − best single (D_v) |" if gain else ""
            out += [f"#### {scen}: {' '.join(groups)}", "", head,
                    "|---|" + "---:|" * (3 * len(groups) + gain)]
            out += ablation_rows(values, scen, exps, groups, 2, str, gain) + [""]
    return out


def section9(values, paper, seeds):
    return section9_summary(values) + ["All metrics, every setting (the script's own table):", ""] \
        + section9_all(values)


SECTIONS = {"1": section1, "2": section2, "3": section3, "9": section9}


# ---------------------------------------------------------------------------------------------
# Parsing the page: the tables of sections 1, 2, 3 and 9 back into the dictionary of load_out.


def decimals_of(text):
    return len(text.split(".")[1]) if "." in text else 0


def parse_cell(text):
    """'83.1 ± 2.4' -> (83.1, 2.4, 1); '—' -> (None, None, 0); '85' -> (85.0, None, 0)."""
    text = text.strip()
    if text in ("—", ""):
        return None, None, 0
    mean, _, ci = text.partition("±")
    try:
        return (float(mean), float(ci) if ci.strip() else None, decimals_of(mean.strip()))
    except ValueError:
        return None


def scenario_of_line(line):
    """The scenario a heading or table label names, or None."""
    text = line.lstrip("#").strip()
    if not (line.startswith("#") or text.endswith(":")):
        return None
    for scen in SCENARIOS:
        if text.startswith(scen) or text.lower().startswith(SCENARIO_TITLE[scen].lower()):
            return scen
    return None


def column_keys(header):
    """Header cells -> [(metric, mode) or None]; metric-row tables give [mode or None]."""
    keys = []
    for name in header:
        name = name.strip()
        if name in MODES:
            keys.append((None, name))
            continue
        metric, _, mode = name.rpartition(" ")
        keys.append((COLUMN_METRIC[metric], ABBREV[mode])
                    if metric in COLUMN_METRIC and mode in ABBREV else None)
    return keys


def keep(values, key, parsed):
    """Store the parsed value unless one with more decimals (or a number for a '—') is there."""
    if parsed is None:
        return
    have = values.get(key)
    if have is None or have[0] is None or (parsed[0] is not None and have[2] < parsed[2]):
        values[key] = parsed


def row_experiment(section, label, seeds_label):
    """The experiment a table row measures, from its section and label cells."""
    by_label = {lab: e for e, lab in SECTION3_ROWS}
    label = label.strip()
    if section == "1":
        m = re.search(r"\*\*(\d+) seeds\*\*", seeds_label)
        return f"preset_paper_{m.group(1)}seeds" if m else "preset_paper"
    if section == "2":
        return "preset_dualgrid"
    if label in by_label:
        return by_label[label]
    name = label.replace(" (earlier default)", "")
    return name if name in FIT else None


def parse_table(values, section, scen, context, lines):
    header = [c for c in lines[0].strip().strip("|").split("|")]
    keys = column_keys(header)
    metric_rows = {lab: m for m, (lab, _) in METRIC_ROWS.items()} | {"D_v [%]": "D_v"}
    for line in lines[2:]:
        cells = line.strip().strip("|").split("|")
        row_scen, first = scen, 0
        if header[0].strip() == "scenario":
            row_scen = cells[0].strip().replace(" ", "_")
            first = 1
        metric = metric_rows.get(cells[0].strip())
        exp = row_experiment(section, cells[first], context)
        for k, c in zip(keys[first + 1:], cells[first + 1:]):
            if k is None or exp is None or row_scen is None:
                continue
            m, mode = k
            m = m or metric
            if m is not None:
                keep(values, (row_scen, exp, m, mode), parse_cell(c))


def load_page(path):
    lines = read_text(path).splitlines()
    values, section, scen, context, i = {}, None, None, "", 0
    while i < len(lines):
        line = lines[i]
        m = re.match(r"## (\d+)\.", line)
        if line.startswith("## "):
            section, scen = (m.group(1) if m else None), None
        elif section in SECTIONS and line.startswith("|"):
            j = i
            while j < len(lines) and lines[j].startswith("|"):
                j += 1
            parse_table(values, section, scen, context, lines[i:j])
            i = j
            continue
        elif scenario_of_line(line):
            scen, context = scenario_of_line(line), line
        i += 1
    if not values:
        fail(f"{path}: expected the tables of sections 1, 2, 3 and 9 of docs/results.md")
    return values


# ---------------------------------------------------------------------------------------------
# Comparison.


def load(source):
    if os.path.isdir(source):
        return load_out(source)[0]
    if os.path.isfile(source):
        return load_page(source)
    fail(f"{source}: expected an OUT folder of scripts/ablation.sh or a Markdown page")


def fmt(v):
    mean, ci, dec = v
    dec = min(dec, 3) if dec else 0
    if mean is None:
        return "—"
    return f"{mean:.{dec}f}" + ("" if ci is None else f" ± {ci:.{dec}f}")


def at_common_precision(old, new):
    """Both sets restricted to their common keys, each value rounded to the coarser of its two
    precisions (a page's values are rounded; an OUT folder's are not)."""
    def rounded(v, dec):
        mean, ci, _ = v
        return (None if mean is None else round(mean, dec),
                None if ci is None else round(ci, dec), dec)
    keys = set(old) & set(new)
    dec = {k: min(old[k][2], new[k][2]) for k in keys}
    return ({k: rounded(old[k], dec[k]) for k in keys}, {k: rounded(new[k], dec[k]) for k in keys})


def moved(a, b):
    if a[0] is None or b[0] is None:
        return a[0] is not b[0]
    return round(abs(b[0] - a[0]), b[2]) > max(a[1] or 0.0, b[1] or 0.0)


def compare_values(old, new, only_moved, metrics):
    print("| scenario | experiment | metric | mode | old | new | new − old | moved |")
    print("|---|---|---|---|---:|---:|---:|---|")
    count = total = 0
    for key in sorted(set(old) & set(new)):
        if metrics and key[2] not in metrics:
            continue
        a, b = old[key], new[key]
        dec = min(max(a[2], 1), 3)
        diff = "—" if a[0] is None or b[0] is None else f"{b[0] - a[0]:+.{dec}f}"
        flag = moved(a, b)
        total += 1
        count += flag
        if flag or not only_moved:
            print(f"| {' | '.join(key)} | {fmt(a)} | {fmt(b[:2] + (dec,))} | {diff} | "
                  f"{'**moved**' if flag else ''} |")
    print(f"\n{count} of {total} values moved by more than the larger CI half-width.")


def relation(values, key_of, a, b, metric):
    """(better mode, apart) for two modes: better is None for a tie at the printed precision,
    apart when the intervals do not overlap; None if either is missing."""
    x, y = values.get(key_of(a)), values.get(key_of(b))
    if x is None or y is None or x[0] is None or y[0] is None:
        return None
    sign = 1 if metric in HIGHER_IS_BETTER else -1
    d = sign * (x[0] - y[0])
    better = None if abs(d) < 0.5 * 10.0 ** -min(x[2], y[2]) else (a if d > 0 else b)
    dec = min(x[2], y[2])
    return better, round(abs(x[0] - y[0]), dec) > round((x[1] or 0.0) + (y[1] or 0.0), dec)


def change_of(old, new):
    """How the relation of two modes changed, or None when it did not."""
    if old == new or old is None or new is None:
        return None if old == new else "appeared or vanished"
    if None in (old[0], new[0]):  # a tie at the printed precision on one side
        return None if old[1] == new[1] else ("now apart" if new[1] else "now within intervals")
    if old[0] != new[0]:
        return "**flipped, intervals apart**" if old[1] or new[1] else "reordered within intervals"
    return "now apart" if new[1] else "now within intervals"


def show(rel, a, b):
    if rel is None:
        return "—"
    if rel[0] is None:
        return f"{a[:3]} = {b[:3]}"
    worse = b if rel[0] == a else a
    return f"{rel[0][:3]} {'>>' if rel[1] else '>'} {worse[:3]}"


def compare_orderings(old, new, metrics):
    print("\nPairs of modes whose relation changed (better first; >> intervals apart):\n")
    print("| scenario | experiment | metric | old | new | change |")
    print("|---|---|---|---|---|---|")
    pairs = [("position", "velocity"), ("position", "dual"), ("velocity", "dual")]
    for scen, exp, metric in sorted({k[:3] for k in set(old) & set(new)}):
        if metrics and metric not in metrics:
            continue
        for a, b in pairs:
            key_of = lambda m: (scen, exp, metric, m)  # noqa: E731
            r_old, r_new = relation(old, key_of, a, b, metric), relation(new, key_of, a, b, metric)
            change = change_of(r_old, r_new)
            if change:
                print(f"| {scen} | {exp} | {metric} | {show(r_old, a, b)} | {show(r_new, a, b)} "
                      f"| {change} |")


def main(argv):
    usage = ("usage: scripts/results_tables.py tables OUT [--section 1|2|3|9]\n"
             "       scripts/results_tables.py compare OLD NEW [--moved] [--metrics M,...]")
    if len(argv) >= 2 and argv[0] == "tables":
        sections = list(SECTIONS)
        if len(argv) == 4 and argv[2] == "--section" and argv[3] in SECTIONS:
            sections = [argv[3]]
        elif len(argv) != 2:
            fail(usage)
        if not os.path.isdir(argv[1]):
            fail(f"{argv[1]}: expected an OUT folder of scripts/ablation.sh")
        values, paper, seeds = load_out(argv[1])
        for s in sections:
            print(f"<!-- section {s} -->\n")
            print("\n".join(SECTIONS[s](values, paper, seeds)))
        return 0
    if len(argv) >= 3 and argv[0] == "compare":
        rest, only_moved, metrics = argv[3:], False, None
        while rest:
            if rest[0] == "--moved":
                only_moved, rest = True, rest[1:]
            elif rest[0] == "--metrics" and len(rest) > 1:
                metrics, rest = set(rest[1].split(",")), rest[2:]
            else:
                fail(f"unknown option '{rest[0]}'\n{usage}")
        old, new = at_common_precision(load(argv[1]), load(argv[2]))
        compare_values(old, new, only_moved, metrics)
        compare_orderings(old, new, metrics)
        return 0
    fail(usage)


if __name__ == "__main__":
    signal.signal(signal.SIGPIPE, signal.SIG_DFL)  # `... | head` ends quietly
    sys.exit(main(sys.argv[1:]))
