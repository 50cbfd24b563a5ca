"""The distributed LOD build against the single-process one: a synthetic terrain of N splats
(default 12,000,000, SH degree 0) written as a binary PLY in chunks, built by
`splatgl convert … tileset.json --scratch-dir` in a process of its own, then by
`splatgl.tiles.build_distributed` on a local Ray cluster (2 CPUs) from a driver process of its
own, at the same bucket size. Reports wall times, peak memory of each process (the driver and
every worker), bytes carried by Ray and through the scratch folder, and checks that the two
tilesets are identical file for file. Not a test: numbers for docs/scale.md.

    target/pyvenv/bin/python python/bench/bench_tiles_ray.py [N] [BUCKET_SPLATS]

Files go under target/tmp/tiles-ray-bench (about 62 bytes a splat for the PLY, as much for the
scratch files, about twice that for each tileset), removed at the end.
"""

import hashlib
import json
import os
import resource
import shutil
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[2]
N = int(sys.argv[1]) if len(sys.argv) > 1 else 12_000_000
BUCKET = int(sys.argv[2]) if len(sys.argv) > 2 else 2_097_152
WORK = REPO / "target" / "tmp" / "tiles-ray-bench"
SPACING = 0.1
PROPS = ["x", "y", "z", "f_dc_0", "f_dc_1", "f_dc_2", "opacity", "scale_0", "scale_1",
         "scale_2", "rot_0", "rot_1", "rot_2", "rot_3"]


def write_terrain(path: Path, n: int) -> None:
    """A rolling heightfield of flat splats 0.1 apart, coloured by height, in chunks."""
    rng = np.random.default_rng(42)
    side = np.sqrt(n) * SPACING
    head = f"ply\nformat binary_little_endian 1.0\nelement vertex {n}\n"
    head += "".join(f"property float {p}\n" for p in PROPS) + "end_header\n"
    with open(path, "wb") as f:
        f.write(head.encode())
        for start in range(0, n, 1 << 20):
            m = min(1 << 20, n - start)
            x, y = rng.uniform(0, side, m), rng.uniform(0, side, m)
            z = 2 * np.sin(x * 0.05) * np.cos(y * 0.07) + 0.5 * np.sin(x * 0.3)
            z += rng.normal(0, 0.02, m)
            t = (z + 2.5) / 5
            a = rng.uniform(0, np.pi, m)
            rows = np.empty((m, 14), np.float32)
            rows[:, 0], rows[:, 1], rows[:, 2] = x, y, z
            rows[:, 3], rows[:, 4], rows[:, 5] = [(c / 0.2820948) for c in (t - 0.5, 0.6 - t,
                                                                            np.full(m, 0.2))]
            rows[:, 6] = 1.5
            rows[:, 7:10] = np.log([SPACING * 0.9, SPACING * 0.5, SPACING * 0.05])
            rows[:, 10], rows[:, 11], rows[:, 12], rows[:, 13] = (np.cos(a / 2), 0, 0,
                                                                  np.sin(a / 2))
            f.write(rows.astype("<f4").tobytes())


def digest(d: Path) -> dict:
    out = {}
    for p in sorted(d.rglob("*")):
        if p.is_file():
            out[str(p.relative_to(d))] = hashlib.sha256(p.read_bytes()).hexdigest()
    return out


def timed_child(argv) -> tuple:
    """Runs argv; (wall s, its peak RSS in MB, stdout)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
    t = time.perf_counter()
    r = subprocess.run(argv, capture_output=True, text=True)
    wall = time.perf_counter() - t
    if r.returncode != 0:
        sys.exit(f"{argv[:3]} failed:\n{r.stderr[-3000:]}")
    peak = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
    return wall, max(peak, before) / 1024, r.stdout, r.stderr


DRIVER = """
import json, sys, ray, splatgl.tiles
ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False)
s = splatgl.tiles.build_distributed(sys.argv[1], sys.argv[2], scratch_dir=sys.argv[3],
                                    bucket_splats=int(sys.argv[4]), progress=lambda *a: None)
print(json.dumps(s))
"""


def main() -> None:
    shutil.rmtree(WORK, ignore_errors=True)
    WORK.mkdir(parents=True)
    ply = WORK / "terrain.ply"
    t = time.perf_counter()
    write_terrain(ply, N)
    print(f"wrote {N} splats ({ply.stat().st_size / 1e6:.0f} MB) in "
          f"{time.perf_counter() - t:.1f} s", flush=True)
    py = sys.executable
    one = [py, "-c", "import sys, splatgl._splatgl as m; sys.exit(m.cli(sys.argv[1:]))",
           "splatgl", "convert", str(ply), str(WORK / "one" / "tileset.json"),
           "--scratch-dir", str(WORK / "s1"), "--bucket-splats", str(BUCKET)]
    wall1, peak1, _, log = timed_child(one)
    print(f"single process: {wall1:.1f} s, peak {peak1:.0f} MB\n  {log.strip().splitlines()[-1]}",
          flush=True)
    want = digest(WORK / "one")
    shutil.rmtree(WORK / "one")
    many = [py, "-c", DRIVER, str(ply), str(WORK / "many"), str(WORK / "s2"), str(BUCKET)]
    wall2, _, out, _ = timed_child(many)
    s = json.loads(out.strip().splitlines()[-1])
    same = digest(WORK / "many") == want
    print(f"distributed (2 CPUs): {wall2:.1f} s wall (build {s['seconds']['total']:.1f} s: "
          + ", ".join(f"{k} {v:.1f}" for k, v in s["seconds"].items() if k != "total") + ")")
    print(f"  driver peak {s['driver_peak_mb']:.0f} MB; workers: "
          + "; ".join(f"pid {p}: {w['tasks']} tasks, peak {w['peak_mb']:.0f} MB"
                      for p, w in s["workers"].items()))
    print(f"  {s['buckets']} buckets (largest {s['largest_bucket']}), {s['ranges']} ranges, "
          f"{s['tiles']} tiles, {s['bytes'] / 1e6:.0f} MB of content; moved by Ray: "
          f"{s['bytes_to_workers']} B to workers, {s['bytes_from_workers']} B back; through "
          f"the scratch folder: {s['scratch_bytes'] / 1e6:.0f} MB")
    print(f"identical tilesets: {same} ({len(want)} files); distributed / single: "
          f"{wall2 / wall1:.2f}x wall")
    shutil.rmtree(WORK, ignore_errors=True)
    if not same:
        sys.exit("the tilesets differ")


if __name__ == "__main__":
    main()
