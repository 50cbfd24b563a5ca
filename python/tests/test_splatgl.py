"""The Python package against the Rust command: same arrays, same images, errors not
crashes. Run by `scripts/test.sh python` (a venv with `pip install .`, then pytest); the real
files come from ../shared/data/real (SOURCES.md). A missing file or binary skips, which fails
under SPLATGL_REQUIRE=all (CI)."""

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import splatgl

REPO = Path(__file__).resolve().parents[2]
DATA = Path(os.environ.get("SPLATGL_DATA", REPO.parent / "shared" / "data" / "real"))
BIN = Path(os.environ.get("SPLATGL_BIN", REPO / "target" / "debug" / "splatgl"))

# One file per format splatgl reads.
FORMATS = [
    "supersplat_fruit_drops_minimal_sh3.ply",
    "playcanvas_biker.compressed.ply",
    "splatapult_test_16splats_sh3.ply",
    "jsplat_unitCube-ascii.ply",
    "bevy_khr_conformance_matrix.glb",
    "bevy_khr_conformance_matrix.gltf",
    "cesium_native_spz2_basic.glb",
    "playcanvas_biker_v4.spz",
    "splat_transform_minimal-v2.spz",
    "splat_transform_minimal.splat",
    "splat_transform_minimal.ksplat",
]


def need(path: Path) -> Path:
    """`path`, or a skip (a failure under SPLATGL_REQUIRE=all) when it is missing."""
    if not path.exists():
        why = f"{path} is missing"
        if os.environ.get("SPLATGL_REQUIRE") == "all":
            pytest.fail(why + " (SPLATGL_REQUIRE=all)")
        pytest.skip(why)
    return path


def splatgl_cli(*args: str) -> subprocess.CompletedProcess:
    """The Rust binary (target/debug/splatgl), checked."""
    r = subprocess.run([str(need(BIN)), *args], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    return r


@pytest.mark.parametrize("name", FORMATS)
def test_every_format_loads_to_the_arrays_the_rust_loader_gives(name, tmp_path):
    src = need(DATA / name)
    cloud = splatgl.load(src)
    n = len(cloud)
    assert n > 0
    assert cloud.positions.shape == (n, 3) and cloud.positions.dtype == np.float32
    assert cloud.scales.shape == (n, 3)
    assert cloud.rotations.shape == (n, 4)
    assert cloud.opacities.shape == (n,)
    k = (cloud.sh_degree + 1) ** 2
    assert cloud.sh.shape == (n, k, 3)
    # The Rust command's PLY of the same file (axes kept) is byte for byte the PLY of
    # Python's arrays: the same splats, the same order, the same values.
    splatgl_cli("convert", str(src), str(tmp_path / "rust.ply"), "--up", "y")
    splatgl.save(cloud, tmp_path / "python.ply")
    assert (tmp_path / "rust.ply").read_bytes() == (tmp_path / "python.ply").read_bytes()


def test_load_bytes_reads_what_load_reads():
    src = need(DATA / "bevy_khr_conformance_matrix.glb")
    a = splatgl.load(src)
    b = splatgl.load_bytes(src.read_bytes(), src.name)
    assert np.array_equal(a.positions, b.positions)
    assert np.array_equal(a.sh, b.sh)
    assert a.meta == b.meta


@pytest.mark.parametrize("backend", ["reference", "gl"])
def test_render_matches_the_command_for_the_same_camera(backend, tmp_path):
    src = need(DATA / "supersplat_fruit_drops_minimal_sh3.ply")
    cloud = splatgl.load(src)
    c = cloud.positions.mean(axis=0)
    radius = float(np.linalg.norm(cloud.positions - c, axis=1).max())
    eye = c + np.array([0.0, -0.3, -2.5]) * radius
    cam = splatgl.Camera.look_at(eye, c, up=(0, -1, 0), fov_y_deg=40, width=200, height=150)
    image = splatgl.render(cloud, cam, backend=backend)
    assert image.shape == (150, 200, 4) and image.dtype == np.float32
    assert image[..., :3].max() > 0.05, "the view misses the scene"
    look = ",".join(str(float(v)) for v in [*eye, *c, 0, -1, 0])
    # GL reads back 8 bits: its PNG; the reference's float PFM.
    out = tmp_path / ("cli.pfm" if backend == "reference" else "cli.png")
    splatgl_cli("render", str(src), "--look-at", look, "--fov", "40", "--width", "200",
                "--height", "150", "--backend", backend, "-o", str(out))
    d = splatgl.compare(image, out)
    assert d["psnr"] >= 60.0, d


def test_render_of_a_trainers_arrays(tmp_path):
    rng = np.random.default_rng(3)
    n = 500
    cloud = splatgl.Cloud.from_arrays(
        positions=rng.normal(size=(n, 3)) * 0.5,
        scales=np.exp(rng.uniform(-4, -2.5, size=(n, 3))),
        rotations=rng.normal(size=(n, 4)),
        opacities=1 / (1 + np.exp(-rng.normal(size=n))),
        colors=rng.uniform(0, 1, size=(n, 3)),
    )
    assert len(cloud) == n and cloud.sh_degree == 0
    np.testing.assert_allclose(np.linalg.norm(cloud.rotations, axis=1), 1.0, rtol=1e-5)
    cam = splatgl.Camera.look_at((0, 0, 4), (0, 0, 0), width=96, height=64)
    img = splatgl.render(cloud, cam, backend="reference")
    assert img[..., 3].max() > 0.5


@pytest.mark.parametrize("ext", ["ply", "glb", "gltf", "spz", "splat"])
def test_arrays_round_trip_through_save_and_load(ext, tmp_path):
    rng = np.random.default_rng(5)
    n = 300
    sh = rng.normal(size=(n, 16, 3)).astype(np.float32) * 0.2
    cloud = splatgl.Cloud.from_arrays(
        rng.uniform(-1, 1, size=(n, 3)),
        rng.uniform(0.01, 0.1, size=(n, 3)),
        np.tile([0.0, 0.0, 0.0, 1.0], (n, 1)),
        rng.uniform(0.1, 0.9, size=n),
        sh=sh,
    )
    path = tmp_path / f"c.{ext}"
    splatgl.save(cloud, path)
    back = splatgl.load(path)
    assert len(back) == n
    # glTF keeps float32; the packed formats quantize.
    tol = 1e-6 if ext in ("ply", "glb", "gltf") else 2e-2
    np.testing.assert_allclose(back.positions, cloud.positions, atol=tol)
    np.testing.assert_allclose(back.opacities, cloud.opacities, atol=max(tol, 1 / 255 + 1e-6))


def test_hostile_input_raises_instead_of_crashing(tmp_path):
    with pytest.raises(splatgl.LoadError):
        splatgl.load(tmp_path / "missing.ply")
    bad = tmp_path / "truncated.ply"
    bad.write_bytes(b"ply\nformat binary_little_endian 1.0\nelement vertex 1000\n"
                    b"property float x\nend_header\n\x00\x00")
    with pytest.raises(splatgl.LoadError, match="truncated.ply"):
        splatgl.load(bad)
    with pytest.raises(splatgl.LoadError):
        splatgl.load_bytes(os.urandom(4096), "noise.glb")
    # A glTF whose buffer escapes its folder is refused, on Windows-style paths too.
    for uri in ["../../secret.bin", "..\\..\\secret.bin", "C:\\x.bin"]:
        doc = tmp_path / "escape.gltf"
        doc.write_text(json.dumps({"asset": {"version": "2.0"},
                                   "buffers": [{"uri": uri, "byteLength": 12}]}))
        with pytest.raises(splatgl.LoadError):
            splatgl.load(doc)
    with pytest.raises(splatgl.LoadError, match="max_splats|splats"):
        splatgl.load(need(DATA / "playcanvas_biker.compressed.ply"), max_splats=10)
    ok = dict(positions=np.zeros((2, 3)), scales=np.ones((2, 3)) * 0.1,
              rotations=[[0, 0, 0, 1]] * 2, opacities=[0.5, 0.5], colors=np.ones((2, 3)))
    for key, value in [("positions", [[0, 0, np.nan]] * 2), ("scales", [[-1, 1, 1]] * 2),
                       ("rotations", [[0, 0, 0, 0]] * 2), ("opacities", [2.0, 0.5]),
                       ("positions", np.zeros((3, 3)))]:
        with pytest.raises(ValueError):
            splatgl.Cloud.from_arrays(**{**ok, key: value})
    with pytest.raises(splatgl.CameraError):
        splatgl.Camera(100, 100, 50, 50, 100, 100, np.diag([2.0, 1, 1, 1]))
    with pytest.raises(splatgl.CameraError):
        splatgl.Camera.look_at((0, 0, 1), (0, 0, 1))
    cloud = splatgl.Cloud.from_arrays(**ok)
    with pytest.raises(ValueError):
        splatgl.render(cloud, splatgl.Camera.look_at((0, 0, 3), (0, 0, 0)), backend="vulkan")
    with pytest.raises(splatgl.SaveError):
        splatgl.save(cloud, tmp_path / "c.txt")


def test_validate_and_compare():
    findings = splatgl.validate(need(DATA / "tiles_tools_UnitSH_legacy.glb"))
    assert findings and all(len(f) == 3 for f in findings)
    a = np.zeros((4, 4, 3), np.float32)
    b = a.copy()
    b[0, 0] = 1.0
    d = splatgl.compare(a, b)
    assert d["pixels_over"] == 1 and d["max_abs"] == 1.0


def test_cameras_json_camera(tmp_path):
    cams = [{"id": 0, "img_name": "a", "width": 64, "height": 48,
             "position": [0, 0, -3], "rotation": [[1, 0, 0], [0, 1, 0], [0, 0, 1]],
             "fx": 60.0, "fy": 60.0}]
    p = tmp_path / "cameras.json"
    p.write_text(json.dumps(cams))
    cam = splatgl.Camera.from_cameras_json(p, 0)
    assert (cam.width, cam.height, cam.fx) == (64, 48, 60.0)
    np.testing.assert_allclose(cam.eye, [0, 0, -3], atol=1e-6)
    with pytest.raises(splatgl.CameraError):
        splatgl.Camera.from_cameras_json(p, 5)
    same = splatgl.Camera(cam.fx, cam.fy, cam.cx, cam.cy, 64, 48, cam.world_to_camera)
    np.testing.assert_allclose(same.world_to_camera, cam.world_to_camera)


def test_conformance_generate_and_run_grade_the_references(tmp_path):
    suite = tmp_path / "suite"
    splatgl.conformance.generate(suite)
    images = tmp_path / "images"
    shutil.copytree(suite / "reference", images)
    report = splatgl.conformance.run(suite, images, out=tmp_path / "report")
    assert report["failed"] == 0 and report["passed"] > 20, report["passed"]
    assert (tmp_path / "report" / "report.html").exists()
    with pytest.raises(splatgl.ConformanceError):
        splatgl.conformance.run(tmp_path / "nothing", images)


def test_the_console_script_is_the_command(tmp_path):
    script = shutil.which("splatgl", path=str(Path(sys.executable).parent))
    assert script, "the splatgl console script is not installed"
    src = need(DATA / "splatapult_test_16splats_sh3.ply")
    r = subprocess.run([script, "info", str(src)], capture_output=True, text=True)
    assert r.returncode == 0 and "16" in r.stdout, r.stdout + r.stderr
    r = subprocess.run([script, "render", "--no-such-flag"], capture_output=True, text=True)
    assert r.returncode == 2 and "no-such-flag" in r.stderr
