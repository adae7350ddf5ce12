#!/usr/bin/env python3
"""softraster against Blender Cycles, per scene: the path-traced reference set.

For every scene of `scenes.py` (11 generated glTF scenes, one per material
feature, plus FlightHelmet and CornellBox, each under two HDRIs):

1. Cycles renders it (`cycles_render.py`, python3.11 with bpy 5.0.1), to a
   linear EXR and a PNG through the "Standard" view transform;
2. softraster renders it with `render.tonemap = "clamp"` and `exposure = 0`
   (the same display transform: sRGB of the clamped linear value), with the
   default `environment.method = "prefiltered"` and with `"sampled"`;
3. `softraster compare --json` measures each against Cycles: mean FLIP and
   mean absolute error (fraction of full scale) over the whole frame.

Prints a Markdown table and writes OUT/cycles.csv. Cycles frames are kept in
OUT and reused unless `--fresh` (they depend only on the scene and the
sample count).

Usage (from the repository root, after `cargo build --release`):
    pip install bpy==5.0.1          # for python3.11
    python3 benches/cycles/run.py [--out /tmp/softraster-cycles] [--samples 128]
        [--only glass-backdrop,anisotropy-discs] [--hdri studio]
"""
import argparse
import csv
import json
import os
import statistics
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, HERE)
import scenes  # noqa: E402


def parse_args():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--out", default="/tmp/softraster-cycles")
    p.add_argument("--softraster", default=os.path.join(ROOT, "target/release/softraster"))
    p.add_argument("--python", default="python3.11", help="the Python that has bpy")
    p.add_argument("--samples", type=int, default=128, help="Cycles samples (denoised)")
    p.add_argument("--sampled", type=int, default=256,
                   help="softraster environment.samples for the sampled column (0: skip it)")
    p.add_argument("--only", help="comma-separated scene names")
    p.add_argument("--hdri", help="only this HDRI")
    p.add_argument("--fresh", action="store_true", help="render Cycles again")
    p.add_argument("--csv", help="also write the table here (e.g. docs/cycles_accuracy.csv)")
    return p.parse_args()


def cycles(a, toml, stem):
    png = stem + ".png"
    if os.path.exists(png) and not a.fresh:
        return png, None
    t = time.time()
    r = subprocess.run([a.python, os.path.join(HERE, "cycles_render.py"), toml, stem,
                        "--samples", str(a.samples)], capture_output=True, text=True)
    if r.returncode != 0 or not os.path.exists(png):
        sys.exit(f"Cycles failed on {toml}:\n{r.stdout[-2000:]}{r.stderr[-2000:]}")
    return png, time.time() - t


def softraster(a, toml, out, extra):
    cmd = [a.softraster, "render", toml, "--out", out, "--frames", "0..1", "--quiet",
           "--set", "output.name=frame"] + [x for s in extra for x in ("--set", s)]
    t = time.time()
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"softraster failed: {' '.join(cmd)}\n{r.stderr}")
    return os.path.join(out, "frame.png"), time.time() - t


def compare(a, ref, test, metric):
    r = subprocess.run([a.softraster, "compare", ref, test, "--metric", metric, "--json",
                        "--threshold", "1000" if metric != "ssim" else "0"],
                       capture_output=True, text=True)
    try:
        return float(json.loads(r.stdout)["files"][0]["value"])
    except (json.JSONDecodeError, KeyError, IndexError, TypeError):
        sys.exit(f"compare printed no value:\n{r.stdout}{r.stderr}")


def main():
    a = parse_args()
    os.makedirs(a.out, exist_ok=True)
    todo = scenes.write_all(a.out)
    if a.only:
        todo = [s for s in todo if s[0] in a.only.split(",")]
    if a.hdri:
        todo = [s for s in todo if s[1] == a.hdri]
    rows = []
    for name, hdri, toml in todo:
        stem = os.path.join(a.out, f"{name}-{hdri}")
        ref, cy_s = cycles(a, toml, stem + "-cycles")
        row = {"scene": name, "hdri": hdri}
        methods = [("prefiltered", [])]
        if a.sampled:
            methods.append(("sampled", ["environment.method=sampled",
                                        f"environment.samples={a.sampled}"]))
        for method, extra in methods:
            test, _ = softraster(a, toml, f"{stem}-{method}", extra)
            row[f"flip_{method}"] = compare(a, ref, test, "flip")
            row[f"mae_{method}"] = compare(a, ref, test, "mae")
        rows.append(row)
        print(f"{name:20} {hdri:10} " + " ".join(
            f"{k}={v:.4f}" for k, v in row.items() if isinstance(v, float))
            + (f"  (cycles {cy_s:.1f} s)" if cy_s else ""), flush=True)
    table(rows, a)


def table(rows, a):
    keys = [k for k in rows[0] if k not in ("scene", "hdri")] if rows else []
    print("\n| scene | hdri | " + " | ".join(keys) + " |")
    print("|---|---|" + "---|" * len(keys))
    for r in rows:
        print(f"| {r['scene']} | {r['hdri']} | " + " | ".join(f"{r[k]:.4f}" for k in keys) + " |")
    for method in ("prefiltered", "sampled"):
        flips = sorted(r[f"flip_{method}"] for r in rows if f"flip_{method}" in r)
        if not flips:
            continue
        # The median of an even count is the mean of the middle two; both
        # are printed, so that a frame just either side of a target shows.
        lo, hi = flips[(len(flips) - 1) // 2], flips[len(flips) // 2]
        print(f"\nFLIP ({method}): median {statistics.median(flips):.4f} (middle frames "
              f"{lo:.4f}, {hi:.4f}), max {flips[-1]:.4f}, {sum(f > 0.10 for f in flips)} above "
              f"0.10, {len(flips)} frames")
    for path in [os.path.join(a.out, "cycles.csv")] + ([a.csv] if a.csv else []):
        with open(path, "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=["scene", "hdri"] + keys)
            w.writeheader()
            for r in rows:
                w.writerow({k: (f"{v:.4f}" if isinstance(v, float) else v) for k, v in r.items()})


if __name__ == "__main__":
    main()
