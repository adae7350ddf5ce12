#!/usr/bin/env python3
"""softraster against Mesa's llvmpipe, side by side, on the same machine.

Runs `softraster bench --case ...` (set up like the harness) and the llvmpipe
harness `../shared/bench/llvmpipe/turntable.py` on the same workloads, the two
interleaved (softraster, llvmpipe, softraster, ...; the order alternates each
repeat), `--repeats` times, and prints for each workload the best (lowest) of
the repeats' steady per-frame medians and their ratio (softraster / llvmpipe:
below 1 is faster). The whole-job rows time `softraster render` of the same
scene as a process (load + 72 frames + PNG files, wall clock) against the
harness's load + frame loop with PNG writing.

Set-up (Debian, as root; see ../shared/bench/llvmpipe/README.md):
    apt-get install -y libgl1-mesa-dri libegl1 libegl-mesa0 libgbm1
    pip install moderngl numpy pillow
    cargo build --release
    python3 benches/anchor.py                 # about 10 minutes
    python3 benches/anchor.py --repeats 1 --cases diablo3-matched
"""
import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def parse_args():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--softraster", default=os.path.join(ROOT, "target/release/softraster"))
    p.add_argument("--harness", default=os.path.join(ROOT, "../shared/bench/llvmpipe"))
    p.add_argument("--assets", default=os.path.join(ROOT, "../shared/assets"))
    p.add_argument("--models", default="/tmp/softraster-bench/models",
                   help="where the harness's prepare.sh puts the models")
    p.add_argument("--repeats", type=int, default=3)
    p.add_argument("--frames", type=int, default=72)
    p.add_argument("--size", type=int, default=700)
    p.add_argument("--threads", type=int, default=None,
                   help="softraster --threads and llvmpipe LP_NUM_THREADS (default: all cores)")
    p.add_argument("--cases", default="all",
                   help="comma-separated workload names (see WORKLOADS), or all")
    p.add_argument("--json", default=None, help="append the raw results (JSON lines) here")
    return p.parse_args()


def workloads(m):
    d1 = f"{m}/diablo3"
    d4 = f"{m}/diablo3_4k"
    tex1 = ["--diffuse", f"{d1}/diablo3_pose_diffuse.tga", "--normal",
            f"{d1}/diablo3_pose_nm_tangent.tga", "--spec", f"{d1}/diablo3_pose_spec.tga"]
    tex4 = ["--diffuse", f"{d4}/diablo3_pose_diffuse_4k.png", "--normal",
            f"{d4}/diablo3_pose_nm_tangent_4k.png", "--spec", f"{d4}/diablo3_pose_spec_4k.png"]
    d3 = ["--obj", f"{d1}/diablo3_pose.obj"] + tex1
    # name: (softraster bench args, harness args)
    return {
        "diablo3-matched": (["--case", "diablo3-matched"], d3),
        "diablo3 msaa 4x": (["--case", "diablo3-matched", "--msaa", "4"], d3 + ["--msaa", "4"]),
        "diablo3 msaa 4x + shadow + floor": (
            ["--case", "diablo3-matched-shadow", "--msaa", "4"],
            d3 + ["--msaa", "4", "--shadow", "1", "--floor", "1"]),
        "diablo3 4k maps": (["--case", "diablo3-4k-matched"],
                            ["--obj", f"{d4}/diablo3_pose.obj"] + tex4),
        "nefertiti (diablo3 maps, spherical UVs)": (
            ["--case", "nefertiti-matched"],
            ["--obj", f"{m}/data/nefertiti.obj", "--up", "z"] + tex1),
    }


def busy_cores(interval=1.0):
    def snap():
        with open("/proc/stat") as f:
            v = [int(x) for x in f.readline().split()[1:9]]
        return sum(v) - v[3] - v[4]
    b0 = snap()
    time.sleep(interval)
    return (snap() - b0) / os.sysconf("SC_CLK_TCK") / interval


def run_softraster(a, args, jsonl):
    if os.path.exists(jsonl):
        os.remove(jsonl)
    cmd = [a.softraster, "bench", "--assets", a.assets, "--frames", str(a.frames),
           "--size", str(a.size), "--json", jsonl] + args
    if a.threads:
        cmd += ["--threads", str(a.threads)]
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    with open(jsonl) as f:
        r = json.loads(f.readline())
    return dict(frame_median_ms=r["frame_median_ms"], load_ms=r["load_ms"],
                render_total_ms=r["render_total_ms"])


def run_llvmpipe(a, args, jsonl, out=None):
    if os.path.exists(jsonl):
        os.remove(jsonl)
    cmd = [sys.executable, os.path.join(a.harness, "turntable.py"), "--size", str(a.size),
           "--frames", str(a.frames), "--quiet", "--json", jsonl] + args
    cmd += ["--out", out] if out else ["--no-write"]
    if a.threads:
        cmd += ["--lp-threads", str(a.threads)]
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    with open(jsonl) as f:
        r = json.loads(f.readline())
    return dict(frame_median_ms=r["frame_median_ms"], load_ms=r["load_ms"],
                render_total_ms=r["render_total_ms"], total_ms=r["total_ms"])


def whole_job_softraster(a, tmp, bench_args):
    """`softraster render` of the bench case's scene, as a process: wall ms."""
    scene = os.path.join(tmp, "whole.toml")
    cmd = [a.softraster, "bench", "--assets", a.assets, "--frames", str(a.frames),
           "--size", str(a.size), "--write-scene", scene] + bench_args
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    out = os.path.join(tmp, "sr_frames")
    shutil.rmtree(out, ignore_errors=True)
    cmd = [a.softraster, "render", scene, "--out", out, "--quiet"]
    if a.threads:
        cmd += ["--threads", str(a.threads)]
    t0 = time.perf_counter()
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    return (time.perf_counter() - t0) * 1e3


def main():
    a = parse_args()
    for p in (a.softraster, os.path.join(a.harness, "turntable.py")):
        if not os.path.exists(p):
            sys.exit(f"not found: {p} (cargo build --release; ../shared beside the repository)")
    if not os.path.isdir(os.path.join(a.models, "diablo3_4k")):
        subprocess.run(["bash", os.path.join(a.harness, "prepare.sh")], check=True,
                       env=dict(os.environ, ASSETS=a.assets, OUT=a.models),
                       stdout=subprocess.DEVNULL)
    wl = workloads(a.models)
    names = list(wl) if a.cases == "all" else [c.strip() for c in a.cases.split(",")]
    for n in names:
        if n not in wl and n != "whole job":
            sys.exit(f"unknown case {n!r}; expected one of {list(wl) + ['whole job']}")
    whole = a.cases == "all" or "whole job" in names
    names = [n for n in names if n != "whole job"]
    best = {n: {} for n in names}
    whole_best = {}
    tmp = tempfile.mkdtemp(prefix="softraster-anchor-")
    raw = open(a.json, "a") if a.json else None
    print(f"machine: {os.cpu_count()} cores; other load before start: {busy_cores():.2f} cores",
          flush=True)
    try:
        for rep in range(a.repeats):
            for n in names:
                sr_args, lp_args = wl[n]
                order = ("sr", "lp") if rep % 2 == 0 else ("lp", "sr")
                for who in order:
                    if who == "sr":
                        r = run_softraster(a, sr_args, os.path.join(tmp, "sr.jsonl"))
                    else:
                        r = run_llvmpipe(a, lp_args, os.path.join(tmp, "lp.jsonl"))
                    prev = best[n].get(who)
                    if prev is None or r["frame_median_ms"] < prev["frame_median_ms"]:
                        best[n][who] = r
                    if raw:
                        raw.write(json.dumps(dict(repeat=rep, case=n, who=who, **r)) + "\n")
                    print(f"  repeat {rep + 1}/{a.repeats} {n:42s} {who}: "
                          f"{r['frame_median_ms']:7.2f} ms/frame", flush=True)
            if whole:
                sr_args, lp_args = wl["diablo3-matched"]
                order = ("sr", "lp") if rep % 2 == 0 else ("lp", "sr")
                for who in order:
                    if who == "sr":
                        ms = whole_job_softraster(a, tmp, sr_args)
                    else:
                        out = os.path.join(tmp, "lp_frames")
                        shutil.rmtree(out, ignore_errors=True)
                        os.makedirs(out)
                        ms = run_llvmpipe(a, lp_args, os.path.join(tmp, "lp.jsonl"),
                                          out=out)["total_ms"]
                    whole_best[who] = min(whole_best.get(who, float("inf")), ms)
                    if raw:
                        raw.write(json.dumps(dict(repeat=rep, case="whole job", who=who,
                                                  total_ms=ms)) + "\n")
                    print(f"  repeat {rep + 1}/{a.repeats} {'whole job (diablo3-matched)':42s} "
                          f"{who}: {ms:7.0f} ms", flush=True)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
        if raw:
            raw.close()
    threads = a.threads or os.cpu_count()
    print()
    print(f"best of {a.repeats} interleaved runs, {a.frames} frames at {a.size}x{a.size}, "
          f"{threads} thread(s) each; steady ms/frame = median of frames 1..{a.frames - 1}")
    print()
    print("| workload | softraster ms/frame | llvmpipe ms/frame | ratio |")
    print("|---|---|---|---|")
    for n in names:
        s, l = best[n]["sr"], best[n]["lp"]
        print(f"| {n} | {s['frame_median_ms']:.2f} | {l['frame_median_ms']:.2f} | "
              f"{s['frame_median_ms'] / l['frame_median_ms']:.2f} |")
    if whole:
        s, l = whole_best["sr"], whole_best["lp"]
        print(f"| whole job: load + {a.frames} frames + PNG files (diablo3-matched) | "
              f"{s:.0f} ms | {l:.0f} ms | {s / l:.2f} |")
    for n in names:
        s, l = best[n]["sr"], best[n]["lp"]
        print(f"load, {n}: softraster {s['load_ms']:.0f} ms (decode + mip chains), "
              f"llvmpipe {l['load_ms']:.0f} ms (parse + decode + upload)")


if __name__ == "__main__":
    main()
