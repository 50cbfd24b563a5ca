"""Load time and peak memory of a 1M-splat PLY (SH degree 3, INRIA layout): splatgl.load
against plyfile + NumPy (the way trainers read them), each in a fresh process, three runs,
the median; then render time of the real scenes with both backends. Not a test: numbers
for docs/python.md and the issue's note.

    target/pyvenv/bin/pip install plyfile==1.1.5
    target/pyvenv/bin/python python/bench/bench_load.py [N]
"""

import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

N = int(sys.argv[1]) if len(sys.argv) > 1 else 1_000_000
REPO = Path(__file__).resolve().parents[2]
DATA = Path(os.environ.get("SPLATGL_DATA", REPO.parent / "shared" / "data" / "real"))

FIELDS = (["x", "y", "z", "nx", "ny", "nz", "f_dc_0", "f_dc_1", "f_dc_2"]
          + [f"f_rest_{i}" for i in range(45)]
          + ["opacity", "scale_0", "scale_1", "scale_2", "rot_0", "rot_1", "rot_2", "rot_3"])


def write_ply(path: Path, n: int) -> None:
    rng = np.random.default_rng(1)
    data = rng.normal(size=(n, len(FIELDS))).astype("<f4")
    data[:, FIELDS.index("scale_0"):FIELDS.index("scale_2") + 1] -= 4.0
    header = "ply\nformat binary_little_endian 1.0\nelement vertex %d\n" % n
    header += "".join(f"property float {f}\n" for f in FIELDS) + "end_header\n"
    with open(path, "wb") as f:
        f.write(header.encode())
        f.write(data.tobytes())


LOADERS = {
    "splatgl": "import splatgl; c = splatgl.load(P); a = (c.positions, c.scales, c.rotations, c.opacities, c.sh)",
    "plyfile": "from plyfile import PlyData; import numpy as np; v = PlyData.read(P)['vertex'].data; "
               "a = np.stack([v[k] for k in v.dtype.names], axis=1).astype(np.float32)",
}


def run(loader: str, path: Path) -> tuple:
    # VmHWM: the peak of this process's own memory (ru_maxrss would carry the parent's
    # across fork and exec).
    code = (f"import time; P = {str(path)!r}; t = time.perf_counter(); "
            f"{LOADERS[loader]}; dt = time.perf_counter() - t; "
            "hwm = [l for l in open('/proc/self/status') if l.startswith('VmHWM')][0]; "
            "print(dt, hwm.split()[1])")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    dt, kb = out.stdout.split()
    return float(dt), int(kb) / 1024


def main() -> None:
    with tempfile.TemporaryDirectory() as d:
        ply = Path(d) / "bench.ply"
        write_ply(ply, N)
        arrays_mb = N * (3 + 3 + 4 + 1 + 48) * 4 / 2**20
        print(f"{N} splats, SH 3: file {ply.stat().st_size / 2**20:.0f} MB, arrays {arrays_mb:.0f} MB")
        base = None
        for loader in LOADERS:
            try:
                runs = [run(loader, ply) for _ in range(3)]
            except subprocess.CalledProcessError as e:
                print(f"{loader}: {e.stderr.strip().splitlines()[-1]}")
                continue
            t = statistics.median(r[0] for r in runs)
            mb = statistics.median(r[1] for r in runs)
            base = base or t
            print(f"{loader:>8}: load {t:.2f} s ({t / base:.2f}× splatgl), peak {mb:.0f} MB "
                  f"({mb / arrays_mb:.2f}× the arrays)")
    import splatgl
    for name in ["supersplat_fruit_drops_minimal_sh3.ply", "playcanvas_biker.compressed.ply"]:
        cloud = splatgl.load(DATA / name)
        c = cloud.positions.mean(axis=0)
        r = float(np.percentile(np.linalg.norm(cloud.positions - c, axis=1), 90))
        cam = splatgl.Camera.look_at(c + np.array([0, -0.5, -2.0]) * r, c, up=(0, -1, 0),
                                     width=1280, height=720)
        for backend in ["reference", "gl"]:
            times = []
            for _ in range(3):
                t = time.perf_counter()
                splatgl.render(cloud, cam, backend=backend)
                times.append(time.perf_counter() - t)
            print(f"render {name} ({len(cloud)} splats) 1280x720 {backend}: "
                  f"{statistics.median(times) * 1e3:.0f} ms (median of 3, engine created each call)")


if __name__ == "__main__":
    main()
