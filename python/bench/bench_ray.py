"""Batch render over Ray workers against one process: four real scenes × N views each, one
`splatgl.Renderer` in this process, then `splatgl.ray.render_views` on a local cluster with 1
and with 2 workers. Not a test: numbers for docs/scale.md.

    target/pyvenv/bin/python python/bench/bench_ray.py [N_VIEWS] [BACKEND]
"""

import os
import sys
import time
from pathlib import Path

import numpy as np
import ray

import splatgl
import splatgl.ray

REPO = Path(__file__).resolve().parents[2]
DATA = Path(os.environ.get("SPLATGL_DATA", REPO.parent / "shared" / "data" / "real"))
N = int(sys.argv[1]) if len(sys.argv) > 1 else 25
BACKEND = sys.argv[2] if len(sys.argv) > 2 else "reference"
SCENES = ["playcanvas_biker.compressed.ply", "playcanvas_guitar.compressed.ply",
          "mujoco_warp_fox_sh0.ply", "supersplat_fruit_drops_minimal_sh3.ply"]


def views(path):
    cloud = splatgl.load(path)
    c = cloud.positions.mean(axis=0)
    r = float(np.percentile(np.linalg.norm(cloud.positions - c, axis=1), 90))
    return [splatgl.Camera.look_at(eye=c + r * np.array([np.sin(a), -0.3, np.cos(a)]), target=c,
                                   up=(0, -1, 0), width=320, height=180)
            for a in np.linspace(0, 2 * np.pi, N, endpoint=False)]


def main():
    paths = [str(DATA / s) for s in SCENES]
    cams = {p: views(p) for p in paths}
    total = sum(len(v) for v in cams.values())
    t = time.perf_counter()
    with splatgl.Renderer(backend=BACKEND) as r:
        for p in paths:
            r.upload(splatgl.load(p))
            r.render_many(cams[p])
    one = time.perf_counter() - t
    print(f"{total} views of {len(paths)} scenes, {BACKEND}, 320x180")
    print(f"one process, one Renderer: {one:6.2f} s ({total / one:5.2f} images/s)")
    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False)
    for workers in (1, 2):
        t = time.perf_counter()
        s = splatgl.ray.render_views(paths, cams, backend=BACKEND, workers=workers)
        wall = time.perf_counter() - t
        print(f"Ray, {workers} worker(s): {wall:6.2f} s ({total / wall:5.2f} images/s; "
              f"inside render_views {s['wall_s']:.2f} s)")
    ray.shutdown()


if __name__ == "__main__":
    main()
