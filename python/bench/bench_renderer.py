"""splatgl.Renderer kept open against one-shot splatgl.render: 100 cameras around the biker
scene (152,746 splats), images per second with each backend. Not a test: numbers for
docs/python.md and docs/scale.md.

    target/pyvenv/bin/python python/bench/bench_renderer.py [N_CAMERAS] [WIDTH HEIGHT]
"""

import os
import sys
import time
from pathlib import Path

import numpy as np

import splatgl

REPO = Path(__file__).resolve().parents[2]
DATA = Path(os.environ.get("SPLATGL_DATA", REPO.parent / "shared" / "data" / "real"))
N = int(sys.argv[1]) if len(sys.argv) > 1 else 100
W, H = (int(sys.argv[2]), int(sys.argv[3])) if len(sys.argv) > 3 else (320, 180)


def cameras(cloud):
    c = cloud.positions.mean(axis=0)
    r = float(np.percentile(np.linalg.norm(cloud.positions - c, axis=1), 90))
    return [splatgl.Camera.look_at(eye=c + r * np.array([np.sin(a), -0.3, np.cos(a)]),
                                   target=c, up=(0, -1, 0), width=W, height=H)
            for a in np.linspace(0, 2 * np.pi, N, endpoint=False)]


def main():
    cloud = splatgl.load(DATA / "playcanvas_biker.compressed.ply")
    cams = cameras(cloud)
    print(f"{len(cloud)} splats, {N} cameras at {W}x{H}")
    for backend in ["gl", "reference"]:
        t = time.perf_counter()
        once = [splatgl.render(cloud, cam, backend=backend) for cam in cams]
        one_shot = time.perf_counter() - t
        t = time.perf_counter()
        with splatgl.Renderer(backend=backend) as r:
            r.upload(cloud)
            kept = r.render_many(cams)
        reused = time.perf_counter() - t
        same = all(np.array_equal(a, b) for a, b in zip(once, kept))
        print(f"{backend:9} one-shot {N / one_shot:7.2f} images/s ({one_shot:6.2f} s)   "
              f"Renderer {N / reused:7.2f} images/s ({reused:6.2f} s)   "
              f"x{one_shot / reused:5.2f}   identical: {same}")


if __name__ == "__main__":
    main()
