#!/usr/bin/env python3
"""The stepper study's report: velocity-level beds against force-level ones.

    report.py --table pipelines/paper/beds.csv --study-table pipelines/stepper-study/beds.csv \
        --velocity docs/validation/stepper-study --reference docs/validation/acceleration/runs \
        -o docs/validation/stepper-study.md CONFIG...

For every CONFIG (a row of either table) it reads the records <CONFIG>-s<seed>.* in
both directories (summary.json, profile.csv, settle.json, pack.time), and writes one
Markdown table: the mean bulk porosity of each stepper's beds ± its standard error
(n), their difference in combined standard errors (pass: at most 2), and the RMSE
between the two mean radial profiles (pass: at most 0.03). A configuration without
force-level records takes its reference porosity from the study table's ref_* columns
(no profile then). The page depends on the records only, so it regenerates identically.
"""

import argparse
import csv
import glob
import json
import math
import os
import re
import sys
from decimal import ROUND_HALF_UP, Decimal

POROSITY_SIGMAS = 2.0
PROFILE_RMSE = 0.03
PELLET_DP_MM = Decimal(10)
SHAPES = {"sphere": "spheres", "cylinder": "cylinders", "ring": "rings"}


def fail(message):
    print(f"stepper-study report: error: {message}", file=sys.stderr)
    sys.exit(2)


def read_rows(path):
    with open(path, newline="") as f:
        return {row["config"]: row for row in csv.DictReader(f) if row["config"] and not row["config"].startswith("#")}


def read_profile(path):
    """(wall distance in mm, void fraction) points, by increasing wall distance."""
    with open(path, newline="") as f:
        points = [(float(r["wall_distance_mm"]), float(r["void_fraction"])) for r in csv.DictReader(f)]
    if not points:
        fail(f"{path}: empty profile")
    return sorted(points)


def interpolate(points, x):
    """Linear interpolation of a profile at wall distance x (inside its range)."""
    lo, hi = 0, len(points) - 1
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if points[mid][0] <= x:
            lo = mid
        else:
            hi = mid
    (x0, y0), (x1, y1) = points[lo], points[hi]
    if x1 == x0:
        return y0
    return y0 + (y1 - y0) * (x - x0) / (x1 - x0)


def beds(directory, config):
    """The records of a configuration's beds in directory, by seed."""
    pattern = re.compile(re.escape(config) + r"-s(\d+)\.summary\.json$")
    found = []
    for path in glob.glob(os.path.join(glob.escape(directory), glob.escape(config) + "-s*.summary.json")):
        match = pattern.search(os.path.basename(path))
        if not match:
            continue
        stem = path[: -len(".summary.json")]
        with open(path) as f:
            summary = json.load(f)
        bed = {"id": os.path.basename(stem), "seed": int(match.group(1)), "porosity": summary["bulk_porosity"]}
        if os.path.exists(stem + ".profile.csv"):
            bed["profile"] = read_profile(stem + ".profile.csv")
        if os.path.exists(stem + ".settle.json"):
            with open(stem + ".settle.json") as f:
                settle = json.load(f)
            bed["settled"] = settle.get("settled")
            bed["build"] = settle.get("build")
        if os.path.exists(stem + ".pack.time"):
            with open(stem + ".pack.time") as f:
                bed["pack_s"] = float(f.read().split()[0])
        found.append(bed)
    return sorted(found, key=lambda b: b["seed"])


def mean_se(values):
    n = len(values)
    mean = sum(values) / n
    if n < 2:
        return mean, None
    var = sum((v - mean) ** 2 for v in values) / (n - 1)
    return mean, math.sqrt(var / n)


def mean_profile(beds_with_profiles, grid):
    return [sum(interpolate(b["profile"], x) for b in beds_with_profiles) / len(beds_with_profiles) for x in grid]


def profile_rmse(velocity, reference):
    """RMSE between the two sides' mean profiles, on the velocity beds' first grid
    restricted to the wall distances every profile covers; and the RMSE the seeds'
    scatter alone would give (None with fewer than two beds a side): the pooled
    per-point standard deviation of a bed about its side's mean, times √(1/na + 1/nb),
    as a root mean square over the grid."""
    a = [b for b in velocity if "profile" in b]
    b = [r for r in reference if "profile" in r]
    if not a or not b:
        return None, None
    every = a + b
    lo = max(p["profile"][0][0] for p in every)
    hi = min(p["profile"][-1][0] for p in every)
    grid = [x for x, _ in a[0]["profile"] if lo <= x <= hi]
    if not grid:
        return None, None
    va, vb = mean_profile(a, grid), mean_profile(b, grid)
    rmse = math.sqrt(sum((p - q) ** 2 for p, q in zip(va, vb)) / len(grid))
    if len(a) < 2 or len(b) < 2:
        return rmse, None
    squares = 0.0
    for side, mean in ((a, va), (b, vb)):
        for bed in side:
            squares += sum((interpolate(bed["profile"], x) - m) ** 2 for x, m in zip(grid, mean))
    pooled = squares / len(grid) / (len(a) + len(b) - 2)
    return rmse, math.sqrt(pooled * (1 / len(a) + 1 / len(b)))


def label(row):
    d = Decimal(row["tube_diameter_mm"])
    n = (d / PELLET_DP_MM).quantize(Decimal("0.01"), rounding=ROUND_HALF_UP).normalize()
    text = f"`{row['config']}`: {SHAPES.get(row['shape'], row['shape'])}, N = {n} (D = {d} mm)"
    if row.get("count"):
        text += f", {row['count']} pellets"
    if row.get("scheme") and row["scheme"] != "one-column":
        text += f", {row['scheme']}"
    return text


def cell(mean, se, n):
    if n == 0:
        return "—"
    if se is None:
        return f"{mean:.4f} ({n})"
    return f"{mean:.4f} ± {se:.4f} ({n})"


def porosity_z(a, b):
    """(difference a − b, in combined standard errors) of two sides' mean porosities, or
    None when a side has fewer than two beds."""
    if len(a) < 2 or len(b) < 2:
        return None
    (ma, sa), (mb, sb) = mean_se([x["porosity"] for x in a]), mean_se([x["porosity"] for x in b])
    return ma - mb, (ma - mb) / math.hypot(sa, sb)


def side_cell(side):
    if not side:
        return "—"
    return cell(*mean_se([b["porosity"] for b in side]), len(side))


def mean_time(side):
    times = [b["pack_s"] for b in side if "pack_s" in b]
    return sum(times) / len(times) if times else None


def read_side(directory, config):
    return beds(directory, config) if directory and os.path.isdir(directory) else []


def step_halving(text, velocity, reference, half, quarter, z_pass, r_pass, z_verdict, r_verdict):
    """The step-halving row of a configuration, and its checks decided again: a failed one
    passes when the force-level beds at a quarter of the substep agree with the velocity-level
    beds and the velocity-level beds at half the step agree with the default's."""

    def shifted(side):
        z = porosity_z(side, velocity)
        text = side_cell(side)
        return text if z is None else f"{text} ({z[1]:+.2f})"

    zq = porosity_z(quarter, velocity)
    zh = porosity_z(half, velocity)
    rmse, _ = profile_rmse(velocity, quarter)
    velocity_converged = zh is None or abs(zh[1]) <= POROSITY_SIGMAS
    by_halving = False
    notes = []
    if z_pass is False and zq is not None:
        if abs(zq[1]) <= POROSITY_SIGMAS and velocity_converged:
            z_pass, z_verdict, by_halving = True, "pass (step halving)", True
            notes.append("porosity: the force-level beds come to the velocity-level ones")
        else:
            notes.append("porosity: not decided")
    if r_pass is False and rmse is not None and len(quarter) >= 2:
        if rmse <= PROFILE_RMSE and velocity_converged:
            r_pass, r_verdict, by_halving = True, "pass (step halving)", True
            notes.append("profile: the force-level beds come to the velocity-level ones")
        else:
            notes.append("profile: not decided")
    if not notes:
        notes.append("nothing to decide" if z_pass is not False and r_pass is not False else "too few beds")
    row = (
        f"| {text} | {side_cell(velocity)} | {shifted(half)} | {shifted(reference)} | {shifted(quarter)} "
        f"| {'—' if rmse is None else f'{rmse:.4f}'} | {'; '.join(notes)} |"
    )
    return row, z_pass, r_pass, z_verdict, r_verdict, by_halving


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--table", required=True)
    parser.add_argument("--study-table", required=True)
    parser.add_argument("--velocity", required=True)
    parser.add_argument("--reference", required=True)
    parser.add_argument("--velocity-half", help="records of the velocity-level stepper at half its step")
    parser.add_argument("--force-quarter", help="records of the force-level stepper at a quarter of its substep")
    parser.add_argument("-o", "--output", required=True)
    parser.add_argument("configs", nargs="+")
    args = parser.parse_args()

    rows = read_rows(args.table)
    study = read_rows(args.study_table)
    lines = []
    halving = []
    decided = []
    verdicts = []
    unsettled = []
    builds = {}
    for config in dict.fromkeys(args.configs):
        row = study.get(config) or rows.get(config)
        if row is None:
            fail(f"{config}: in neither {args.table} nor {args.study_table}")
        velocity = read_side(args.velocity, config)
        reference = read_side(args.reference, config)
        half = read_side(args.velocity_half, config)
        quarter = read_side(args.force_quarter, config)
        for b in velocity:
            if b.get("settled") is False:
                unsettled.append(b["id"])
            builds[b.get("build") or "not recorded"] = builds.get(b.get("build") or "not recorded", 0) + 1

        v_mean, v_se = mean_se([b["porosity"] for b in velocity]) if velocity else (None, None)
        if reference:
            f_mean, f_se = mean_se([b["porosity"] for b in reference])
            f_n, f_cell = len(reference), None
        elif row.get("ref_porosity"):
            f_mean, f_se, f_n = float(row["ref_porosity"]), float(row["ref_se"]), int(row["ref_n"])
            f_cell = f"{f_mean:.4f} ± {f_se:.4f} ({f_n}; {row['ref_source']})"
        else:
            f_mean, f_se, f_n, f_cell = None, None, 0, None
        f_cell = f_cell or cell(f_mean, f_se, f_n)

        if velocity and f_n and v_se is not None and f_se is not None:
            z = (v_mean - f_mean) / math.hypot(v_se, f_se)
            z_cell, z_pass = f"{v_mean - f_mean:+.4f} ({z:+.2f})", abs(z) <= POROSITY_SIGMAS
            z_verdict = "pass" if z_pass else "**fail**"
        elif velocity and f_n:
            z_cell, z_pass, z_verdict = f"{v_mean - f_mean:+.4f}", None, "— (n < 2)"
        else:
            z_cell, z_pass, z_verdict = "—", None, "—"
        rmse, noise = profile_rmse(velocity, reference)
        if rmse is None:
            r_cell, r_pass, r_verdict = "—", None, "—"
        elif len(velocity) < 2 or len(reference) < 2:
            r_cell, r_pass, r_verdict = f"{rmse:.4f}", None, "— (n < 2)"
        else:
            r_pass = rmse <= PROFILE_RMSE
            r_cell, r_verdict = f"{rmse:.4f}", "pass" if r_pass else "**fail**"
        if noise is not None:
            r_cell += f" ({noise:.4f})"
        if half or quarter:
            row_text, z_pass, r_pass, z_verdict, r_verdict, by_halving = step_halving(
                label(row), velocity, reference, half, quarter, z_pass, r_pass, z_verdict, r_verdict
            )
            halving.append(row_text)
            if by_halving:
                decided.append(config)
        t_v, t_f = mean_time(velocity), mean_time(reference)
        t_cell = " / ".join("—" if t is None else f"{t:.0f}" for t in (t_v, t_f))
        lines.append(
            f"| {label(row)} | {cell(v_mean, v_se, len(velocity))} | {f_cell} | {z_cell} | {z_verdict} "
            f"| {r_cell} | {r_verdict} | {t_cell} |"
        )
        verdicts.append((config, z_pass, r_pass))

    compared = [v for v in verdicts if v[1] is not None]
    failed = [c for c, z, r in verdicts if z is False or r is False]
    pending = [c for c, z, _ in verdicts if z is None]
    if not compared:
        status = "No configuration has both sides with two beds or more yet: nothing is decided."
    elif failed:
        status = f"**{len(failed)} of {len(compared)} compared configurations fail:** " + ", ".join(failed) + "."
    else:
        status = f"All {len(compared)} compared configurations pass."
    if decided:
        status += " Decided by the step halving (below): " + ", ".join(decided) + "."
    if compared and pending:
        status += " Not compared yet (fewer than two beds on a side): " + ", ".join(pending) + "."

    page = [
        "# The steppers' equivalence study",
        "",
        "Beds packed by `pack --stepper velocity` (`pack`'s default) against the force-level beds",
        "(`--stepper acceleration`, the paper's formulation) of the same cases: the paper's validation tubes (its case files, bit for bit, poured 30 mm above the bed surface,",
        "with the stepper changed; the force-level records are the force-level paper study's, in",
        "[acceleration/runs/](acceleration/runs/)) and the 690-sphere batch bed. Written by `make stepper-study-report`",
        "(`pipelines/stepper-study/report.py`) from the records in",
        "[stepper-study/](stepper-study/); how to run the study:",
        "[reproducing.md](reproducing.md#the-steppers-equivalence-study).",
        "",
        "Bulk porosity: mean over the seeds ± standard error (n beds); the difference is velocity −",
        f"force-level, with in brackets that difference in combined standard errors, √(s.e.v² + s.e.f²):",
        f"pass within {POROSITY_SIGMAS:g}. Profile: the RMSE between the two steppers' mean radial void",
        "fraction profiles (each bed's profile interpolated onto the first velocity bed's wall distances),",
        f"pass at most {PROFILE_RMSE:g}; in brackets the RMSE the seeds' scatter alone would give (the pooled",
        "per-point standard deviation of a bed's profile times √(1/nv + 1/nf)). A verdict needs two beds or",
        "more of each stepper. Pack: mean wall seconds of `pack` per bed, velocity / force-level",
        "(different engines and machines: see reproducing.md).",
        "",
        status,
        "",
        "Where a configuration fails, halving each stepper's step decides which of the two is off:",
        "[convergence in the step](../engine.md#convergence-in-the-step) (`pipelines/step-convergence.sh`).",
        "",
        "| configuration | velocity ε ± s.e. (n) | force-level ε ± s.e. (n) | difference (in s.e.) | porosity "
        "| profile RMSE (scatter) | profile | pack s, v / f |",
        "|---|---|---|---|---|---|---|---|",
        *lines,
        "",
    ]
    if halving:
        page += [
            "## Step halving",
            "",
            "The failing configurations packed again at a smaller step: the velocity-level stepper at half",
            "its step (`--step-travel` and `--max-step` halved), the force-level stepper at a quarter of its",
            "substep (`--substep-scale 0.25`); records in [stepper-study/velocity-half/](stepper-study/velocity-half/) and",
            "[stepper-study/force-quarter/](stepper-study/force-quarter/). In brackets: the difference from the velocity-level",
            "beds at the default step in combined standard errors. A failing check passes by step halving",
            "when the force-level beds at a quarter of the substep agree with the velocity-level beds (the",
            "same two tests) and the velocity-level beds at half the step agree with the default's.",
            "",
            "| configuration | velocity, default | velocity, half step | force-level, substep × 1 | force-level, substep × ¼ "
            "| profile RMSE, velocity / ¼ | decision |",
            "|---|---|---|---|---|---|---|",
            *halving,
            "",
        ]
    if unsettled:
        page += [
            "Velocity-level beds that reached their time limit without settling (measured at their last",
            "frame): " + ", ".join(unsettled) + ".",
            "",
        ]
    if builds:
        page += [
            "`pack` builds of the velocity-level beds: "
            + ", ".join(f"{b} ({n})" for b, n in sorted(builds.items()))
            + ".",
            "",
        ]
    text = "\n".join(page)
    tmp = args.output + ".tmp"
    with open(tmp, "w") as f:
        f.write(text)
    os.replace(tmp, args.output)
    print(f"stepper-study report: {len(compared)} of {len(verdicts)} configurations compared; wrote {args.output}")


if __name__ == "__main__":
    main()
