#!/usr/bin/env python3
"""Thumbnails of a model library in one softraster run.

Makes N small models (cubes, tetrahedra and spheres of a few hundred
triangles, as OBJ, STL and PLY), adds the repository's models and, with
--shared, every model of ../shared/assets, renders them all with one
`softraster render FOLDER` at 128x128 in the default look, and prints
thumbnails per second, wall time per input and the per-file p50/p99 of
the JSON lines' seconds. --f3d renders the same files with f3d, one
process per file, for comparison. --rss samples the process's resident
memory while it runs (for the "flat over 10,000 inputs" check).

    python3 benches/thumbnails.py --count 500 --shared
    python3 benches/thumbnails.py --count 10000 --rss --no-repo
"""

import argparse
import json
import math
import os
import shutil
import subprocess
import sys
import tempfile
import threading
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
EXTS = (".gltf", ".glb", ".obj", ".stl", ".ply", ".fbx", ".usd", ".usda", ".usdc", ".usdz", ".3mf")


def sphere(n_lat, n_lon, r):
    verts = []
    for i in range(n_lat + 1):
        th = math.pi * i / n_lat
        for j in range(n_lon):
            ph = 2 * math.pi * j / n_lon
            verts.append((r * math.sin(th) * math.cos(ph), r * math.cos(th), r * math.sin(th) * math.sin(ph)))
    faces = []
    for i in range(n_lat):
        for j in range(n_lon):
            a = i * n_lon + j
            b = i * n_lon + (j + 1) % n_lon
            c, d = a + n_lon, b + n_lon
            if i > 0:
                faces.append((a, b, d))
            if i < n_lat - 1:
                faces.append((a, d, c))
    return verts, faces


def cube(s):
    v = [(x * s, y * s, z * s) for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]
    f = [(0, 1, 3), (0, 3, 2), (4, 6, 7), (4, 7, 5), (0, 4, 5), (0, 5, 1),
         (2, 3, 7), (2, 7, 6), (0, 2, 6), (0, 6, 4), (1, 5, 7), (1, 7, 3)]
    return v, f


def tetra(s):
    v = [(s, s, s), (-s, -s, s), (-s, s, -s), (s, -s, -s)]
    return v, [(0, 1, 2), (0, 3, 1), (0, 2, 3), (1, 3, 2)]


def write(path, verts, faces):
    ext = os.path.splitext(path)[1]
    with open(path, "w") as f:
        if ext == ".obj":
            f.writelines("v %g %g %g\n" % v for v in verts)
            f.writelines("f %d %d %d\n" % (a + 1, b + 1, c + 1) for a, b, c in faces)
        elif ext == ".ply":
            f.write("ply\nformat ascii 1.0\nelement vertex %d\nproperty float x\nproperty float y\n"
                    "property float z\nelement face %d\nproperty list uchar int vertex_indices\nend_header\n"
                    % (len(verts), len(faces)))
            f.writelines("%g %g %g\n" % v for v in verts)
            f.writelines("3 %d %d %d\n" % fc for fc in faces)
        else:
            f.write("solid m\n")
            for a, b, c in faces:
                f.write("facet normal 0 0 0\nouter loop\n")
                for k in (a, b, c):
                    f.write("vertex %g %g %g\n" % verts[k])
                f.write("endloop\nendfacet\n")
            f.write("endsolid m\n")


def make_library(dir, count, repo, shared):
    """The models, as files under `dir` (the repository's and shared ones
    linked in, not copied)."""
    kinds = ["obj", "stl", "ply"]
    for k in range(count):
        shape = k % 3
        if shape == 0:
            v, f = cube(0.5 + 0.1 * (k % 7))
        elif shape == 1:
            v, f = tetra(0.6 + 0.1 * (k % 5))
        else:
            v, f = sphere(10 + k % 6, 16 + k % 8, 1.0)
        sub = os.path.join(dir, "gen", "%03d" % (k // 1000))
        os.makedirs(sub, exist_ok=True)
        write(os.path.join(sub, "m%05d.%s" % (k, kinds[k % 3])), v, f)
    sources = []
    if repo:
        sources.append(os.path.join(ROOT, "assets"))
    if shared:
        sources.append(os.path.join(ROOT, "..", "shared", "assets"))
    for s in sources:
        if os.path.isdir(s):
            os.symlink(os.path.abspath(s), os.path.join(dir, os.path.basename(os.path.dirname(s)) + "-" + os.path.basename(s)))


def model_files(dir):
    out = []
    for root, _, files in os.walk(dir, followlinks=True):
        out.extend(os.path.join(root, f) for f in files if f.lower().endswith(EXTS))
    return sorted(out)


def pct(xs, p):
    xs = sorted(xs)
    return xs[min(len(xs) - 1, int(p / 100 * len(xs)))] if xs else float("nan")


def sample_rss(proc, out, every):
    t0 = time.time()
    while proc.poll() is None:
        try:
            with open("/proc/%d/status" % proc.pid) as f:
                for line in f:
                    if line.startswith("VmRSS:"):
                        out.append((time.time() - t0, int(line.split()[1]) / 1024))
        except OSError:
            break
        time.sleep(every)


def run_softraster(bin, lib, out, size, rss):
    cmd = [bin, "render", lib, "--out", out, "--progress", "json",
           "--set", "output.width=%d" % size, "--set", "output.height=%d" % size]
    t0 = time.time()
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    samples = []
    sampler = None
    if rss:
        sampler = threading.Thread(target=sample_rss, args=(proc, samples, 1.0))
        sampler.start()
    lines = proc.stdout.read().splitlines()
    proc.wait()
    wall = time.time() - t0
    if sampler:
        sampler.join()
    inputs = [json.loads(l) for l in lines if '"event":"input"' in l]
    return wall, inputs, samples, proc.returncode


def run_f3d(files, out, size):
    """f3d 4's Python module (`pip install f3d`; its wheel has no command
    line): one offscreen engine for every file, each file cleared, loaded,
    rendered and saved; per-file seconds."""
    import f3d

    engine = f3d.Engine.create(True)
    engine.window.size = (size, size)
    times = []
    for k, f in enumerate(files):
        t0 = time.time()
        try:
            engine.scene.clear()
            engine.scene.add(f)
            engine.window.render_to_image().save(os.path.join(out, "%05d.png" % k))
        except Exception as e:  # f3d refuses some files; count its time
            print("f3d: %s: %s" % (f, e), file=sys.stderr)
        times.append(time.time() - t0)
    return times


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--count", type=int, default=500)
    ap.add_argument("--size", type=int, default=128)
    ap.add_argument("--shared", action="store_true", help="add ../shared/assets")
    ap.add_argument("--no-repo", action="store_true", help="leave out the repository's assets")
    ap.add_argument("--f3d", action="store_true", help="also time f3d, one process per file")
    ap.add_argument("--rss", action="store_true", help="sample resident memory every second")
    ap.add_argument("--bin", default=os.path.join(ROOT, "target", "release", "softraster"))
    ap.add_argument("--keep", metavar="DIR", help="write the thumbnails to DIR and keep them")
    a = ap.parse_args()
    work = tempfile.mkdtemp(prefix="thumbs-")
    try:
        lib = os.path.join(work, "lib")
        os.makedirs(lib)
        make_library(lib, a.count, not a.no_repo, a.shared)
        files = model_files(lib)
        out = a.keep or os.path.join(work, "out")
        wall, inputs, samples, code = run_softraster(a.bin, lib, out, a.size, a.rss)
        secs = [i["seconds"] for i in inputs]
        status = {}
        for i in inputs:
            status[i["status"]] = status.get(i["status"], 0) + 1
        print("softraster: %d inputs (%s), exit %d" % (len(inputs), ", ".join("%d %s" % (v, k) for k, v in sorted(status.items())), code))
        print("  %.2f s wall, %.1f thumbnails/s, %.1f ms wall per input" % (wall, len(inputs) / wall, wall / max(1, len(inputs)) * 1e3))
        print("  per file: p50 %.1f ms, p99 %.1f ms, max %.1f ms (%s)" % (
            pct(secs, 50) * 1e3, pct(secs, 99) * 1e3, max(secs) * 1e3,
            max(inputs, key=lambda i: i["seconds"])["path"]))
        gen = [i["seconds"] for i in inputs if "/gen/" in i["path"]]
        if gen:
            print("  generated models alone: p50 %.1f ms, p99 %.1f ms" % (pct(gen, 50) * 1e3, pct(gen, 99) * 1e3))
        if samples:
            step = max(1, len(samples) // 12)
            print("  resident memory (s: MiB): " + ", ".join("%.0f: %.0f" % s for s in samples[::step] + samples[-1:]))
        if a.f3d:
            try:
                import f3d  # noqa: F401
            except ImportError:
                print("f3d: not installed (pip install f3d)")
            else:
                out = os.path.join(work, "f3d")
                os.makedirs(out)
                t = run_f3d(files, out, a.size)
                print("f3d: %d files, %.2f s, %.1f thumbnails/s, per file p50 %.1f ms, p99 %.1f ms" % (
                    len(t), sum(t), len(t) / sum(t), pct(t, 50) * 1e3, pct(t, 99) * 1e3))
    finally:
        shutil.rmtree(work, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
