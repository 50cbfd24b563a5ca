"""Hostile arguments to the Python package: the CLI's rules hold here too. No file is opened
that an API says it will not open, no allocation above the CLI's limits (a splat count, a
16384-pixel image side) comes from a crafted array, name or camera, and every refusal is an
exception with a message, never a crash."""

import base64
import json
import os
from pathlib import Path

import numpy as np
import pytest

import splatgl


def unit_cloud(n: int = 4) -> splatgl.Cloud:
    return splatgl.Cloud.from_arrays(
        np.zeros((n, 3)), np.full((n, 3), 0.1), np.tile([0, 0, 0, 1.0], (n, 1)),
        np.full(n, 0.5), colors=np.full((n, 3), 0.5))


def gltf_with_external_buffer(tmp_path: Path) -> bytes:
    """A glTF whose splat data is in `x.bin` beside it (written to `tmp_path`)."""
    splatgl.save(unit_cloud(), tmp_path / "x.gltf")
    doc = json.loads((tmp_path / "x.gltf").read_text())
    for b in doc["buffers"]:
        uri = b["uri"]
        if uri.startswith("data:"):
            (tmp_path / "x.bin").write_bytes(base64.b64decode(uri.split(",", 1)[1]))
            b["uri"] = "x.bin"
    return json.dumps(doc).encode()


@pytest.mark.parametrize("name", ["x.json", "x.GLTF", "x", None, "x.gltf", "sub/../x.gltf"])
def test_load_bytes_opens_no_file_whatever_the_name(name, tmp_path, monkeypatch):
    data = gltf_with_external_buffer(tmp_path)
    # The buffer sits in the working directory, where a name-relative read would find it.
    monkeypatch.chdir(tmp_path)
    assert len(splatgl.load(write(tmp_path, data))) == 4  # from its path, the buffer loads
    with pytest.raises(splatgl.LoadError, match="opens no file|external buffer"):
        splatgl.load_bytes(data, name)


def write(tmp_path: Path, data: bytes) -> Path:
    p = tmp_path / "copy.gltf"
    p.write_bytes(data)
    return p


def test_load_bytes_reads_no_sog_texture_from_the_working_directory(tmp_path, monkeypatch):
    import zipfile
    splatgl.save(unit_cloud(), tmp_path / "x.sog")
    zipfile.ZipFile(tmp_path / "x.sog").extractall(tmp_path)  # the unbundled form
    out = tmp_path / "meta.json"
    assert any(tmp_path.glob("*.webp")) and len(splatgl.load(out)) == 4
    monkeypatch.chdir(tmp_path)
    for name in ["meta.json", "x", None]:
        with pytest.raises(splatgl.LoadError):
            splatgl.load_bytes(out.read_bytes(), name)


def test_a_cameras_json_camera_is_held_to_the_image_size_limit(tmp_path):
    cam = {"id": 0, "img_name": "a", "width": 65536, "height": 65536,
           "position": [0, 0, -3], "rotation": [[1, 0, 0], [0, 1, 0], [0, 0, 1]],
           "fx": 100.0, "fy": 100.0}
    p = tmp_path / "cameras.json"
    p.write_text(json.dumps([cam]))
    with pytest.raises(ValueError, match="16384"):
        splatgl.Camera.from_cameras_json(p)
    # Resized within the limit it is fine.
    c = splatgl.Camera.from_cameras_json(p, width=64, height=64)
    assert (c.width, c.height) == (64, 64)


@pytest.mark.parametrize("size", [(0, 10), (10, 0), (16385, 10), (2**31, 2**31)])
def test_cameras_outside_the_image_size_limit_are_refused(size):
    with pytest.raises((ValueError, OverflowError)):
        splatgl.Camera(100, 100, 5, 5, size[0], size[1], np.eye(4))


def test_broadcast_arrays_beyond_the_splat_limit_are_refused_before_any_copy():
    n = 10**9  # a broadcast view: no memory until something copies it (float64 → float32)
    big3 = np.broadcast_to(np.zeros(3), (n, 3))
    big4 = np.broadcast_to(np.array([0, 0, 0, 1.0]), (n, 4))
    with pytest.raises(ValueError, match="max_splats"):
        splatgl.Cloud.from_arrays(big3, big3, big4, np.broadcast_to(0.5, (n,)), colors=big3)
    # Within the limit, broadcast inputs are copied safely into a cloud of their own.
    m = 1000
    c = splatgl.Cloud.from_arrays(
        np.broadcast_to(np.zeros(3), (m, 3)), np.broadcast_to(np.full(3, 0.1), (m, 3)),
        np.broadcast_to(np.array([0, 0, 0, 1.0]), (m, 4)), np.broadcast_to(0.5, (m,)),
        colors=np.broadcast_to(np.full(3, 0.5), (m, 3)))
    assert len(c) == m
    c.positions[0, 0] = 7.0
    assert c.positions[1, 0] == 0.0
    with pytest.raises(ValueError, match="max_splats"):
        splatgl.Cloud.from_arrays(
            np.zeros((5, 3)), np.ones((5, 3)), np.tile([0, 0, 0, 1.0], (5, 1)),
            np.ones(5) * 0.5, colors=np.ones((5, 3)), max_splats=4)


@pytest.mark.parametrize("field,value,match", [
    ("scales", 1e20, "overflows"),
    ("scales", -1.0, "≥ 0"),
    ("scales", np.inf, "not finite"),
    ("positions", np.nan, "not finite"),
    ("rotations", 0.0, "zero quaternion"),
    ("opacities", 1.5, "outside"),
])
def test_arrays_break_the_loader_contract_only_with_an_error(field, value, match):
    arrays = {"positions": np.zeros((3, 3)), "scales": np.full((3, 3), 0.1),
              "rotations": np.tile([0, 0, 0, 1.0], (3, 1)), "opacities": np.full(3, 0.5)}
    arrays[field] = arrays[field].copy()
    arrays[field][1] = value
    with pytest.raises(ValueError, match=match):
        splatgl.Cloud.from_arrays(**arrays, colors=np.full((3, 3), 0.5))


def test_compare_refuses_images_beyond_the_size_limit_before_copying():
    huge = np.broadcast_to(np.zeros((1, 1, 4)), (65536, 65536, 4))
    small = np.zeros((4, 4, 4), np.float32)
    with pytest.raises(ValueError, match="16384"):
        splatgl.compare(huge, huge)
    with pytest.raises(ValueError):
        splatgl.compare(small, np.zeros((4, 4, 2), np.float32))
    assert splatgl.compare(small, small)["pixels_over"] == 0


def test_error_messages_escape_terminal_control_characters():
    ply = b"ply\nformat ascii 1.0\nelement vertex 1\nproperty \x1b]0;t\x07float x\nend_header\n1\n"
    with pytest.raises(splatgl.LoadError) as e:
        splatgl.load_bytes(ply, "x.ply")
    assert "\x1b" not in str(e.value) and "\\u{1b}" in str(e.value)


def test_load_reads_files_and_never_maps_them(tmp_path):
    """A file truncated under a memory map kills the process (SIGBUS): the package reads.
    While three loads of a 100 MB file run (the GIL released), a thread watches this
    process's mappings for the file; on a build that maps it, the mapping lasts the whole
    parse and is seen."""
    maps = Path("/proc/self/maps")
    if not maps.exists():
        pytest.skip("no /proc/self/maps on this platform")
    import threading
    n = 400_000
    fields = (["x", "y", "z", "f_dc_0", "f_dc_1", "f_dc_2"] + [f"f_rest_{i}" for i in range(45)]
              + ["opacity", "scale_0", "scale_1", "scale_2", "rot_0", "rot_1", "rot_2", "rot_3"])
    data = np.random.default_rng(1).normal(size=(n, len(fields))).astype("<f4")
    p = tmp_path / "big.ply"
    header = f"ply\nformat binary_little_endian 1.0\nelement vertex {n}\n"
    header += "".join(f"property float {f}\n" for f in fields) + "end_header\n"
    p.write_bytes(header.encode() + data.tobytes())
    seen, stop = [], threading.Event()

    def watch():
        while not stop.is_set():
            if str(p) in maps.read_text():
                seen.append(True)

    t = threading.Thread(target=watch)
    t.start()
    try:
        for _ in range(3):
            assert len(splatgl.load(p)) > 0
    finally:
        stop.set()
        t.join()
    assert not seen, "the file was memory-mapped"
