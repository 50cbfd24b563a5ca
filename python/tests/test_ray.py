"""splatgl.ray on a local Ray cluster started here (2 CPUs): a batch render spread over
workers gives splatgl.render's images, returned or written as PNG; conformance runs of many
image sets in parallel give the reports one run gives. Ray is the optional `ray` extra: where
it is missing these tests skip, which fails under SPLATGL_REQUIRE=all (CI installs it)."""

import os
import shutil
import sys

import numpy as np
import pytest

import splatgl

try:
    import ray
except ImportError:
    ray = None


@pytest.fixture(scope="module")
def cluster(tmp_path_factory):
    if ray is None:
        why = "ray is not installed (pip install 'splatgl[ray]')"
        if os.environ.get("SPLATGL_REQUIRE") == "all":
            pytest.fail(why + " (SPLATGL_REQUIRE=all)")
        pytest.skip(why)
    import splatgl.ray  # noqa: F401  (the module under test)
    # Workers inherit this: a test arms it by creating the marker's folder (splatgl.tiles).
    os.environ["SPLATGL_TEST_KILL_ONCE"] = str(tmp_path_factory.mktemp("kill") / "armed" / "x")
    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False)
    yield os.environ["SPLATGL_TEST_KILL_ONCE"]
    ray.shutdown()


def scenes(tmp_path, n=3):
    paths = []
    for k in range(n):
        rng = np.random.default_rng(k)
        m = 200 + 50 * k
        q = rng.normal(size=(m, 4))
        c = splatgl.Cloud.from_arrays(
            rng.uniform(-1, 1, (m, 3)), rng.uniform(0.02, 0.2, (m, 3)),
            q / np.linalg.norm(q, axis=1, keepdims=True), rng.uniform(0.2, 1, m),
            sh=rng.normal(0, 0.3, (m, 4, 3)))
        p = tmp_path / f"scene{k}.ply"
        splatgl.save(c, p)
        paths.append(p)
    return paths


def cams():
    return [splatgl.Camera.look_at(eye=(np.sin(a) * 3, 0.4, np.cos(a) * 3), target=(0, 0, 0),
                                   width=40, height=30) for a in (0.0, 1.0, 2.0)]


def test_a_batch_render_on_workers_gives_the_one_shot_images(cluster, tmp_path):
    import splatgl.ray
    paths, views = scenes(tmp_path), cams()
    seen = []
    summary = splatgl.ray.render_views(paths, views, backend="reference", progress=seen.append)
    assert summary["workers"] == 2 and summary["views"] == 9 and len(seen) == 3
    assert [e["scene"] for e in summary["scenes"]] == [str(p) for p in paths]
    for entry, path in zip(summary["scenes"], paths):
        cloud = splatgl.load(path)
        assert entry["splats"] == len(cloud) and entry["backend"] == "reference"
        for img, cam in zip(entry["images"], views):
            assert np.array_equal(img, splatgl.render(cloud, cam, backend="reference"))
    # Both workers took part (two scenes at once, the third to whichever finished first).
    assert len({e["worker"] for e in summary["scenes"]}) == 2


def test_a_batch_render_writes_each_scenes_images_as_png(cluster, tmp_path):
    import splatgl.ray
    paths, views = scenes(tmp_path, 2), cams()
    per_scene = {paths[0]: views[:1], paths[1]: views}
    summary = splatgl.ray.render_views(paths, per_scene, out_dir=tmp_path / "out",
                                       backend="auto", width=20, height=15)
    first, second = summary["scenes"]
    assert len(first["images"]) == 1 and len(second["images"]) == 3
    assert first["images"][0] == str(tmp_path / "out" / "scene0" / "0000.png")
    cloud = splatgl.load(paths[1])
    with splatgl.Renderer(backend=second["backend"], width=20, height=15) as r:
        r.upload(cloud)
        for png, cam in zip(second["images"], views):
            c = splatgl.compare(png, r.render(cam))
            assert c["max_abs"] <= 0.5 / 255 + 1e-6, c


def test_conformance_runs_in_parallel_give_the_reports_of_single_runs(cluster, tmp_path):
    import splatgl.ray
    suite = tmp_path / "suite"
    splatgl.conformance.generate(suite)
    good, bad = tmp_path / "good", tmp_path / "bad"
    shutil.copytree(suite / "reference", good)
    shutil.copytree(suite / "reference", bad)
    # One image of the second set blanked: its (required) asset fails, nothing else changes.
    # (The runner reads CAMERA.pfm before CAMERA.png.)
    victim = bad / "attr_position_types" / "front"
    head = victim.with_suffix(".png").read_bytes()[16:24]  # IHDR: width, height (big endian)
    w, h = int.from_bytes(head[:4], "big"), int.from_bytes(head[4:], "big")
    splatgl.save_image(np.zeros((h, w, 4), np.float32), victim.with_suffix(".pfm"))
    reports = splatgl.ray.conformance_runs(suite, [good, bad], out_dirs=[tmp_path / "rg", tmp_path / "rb"])
    for report, images in zip(reports, [good, bad]):
        single = splatgl.conformance.run(suite, images)
        assert (report["passed"], report["failed"]) == (single["passed"], single["failed"])
    assert reports[0]["failed"] == 0 and reports[1]["failed"] >= 1
    assert (tmp_path / "rb" / "report.html").exists()


def test_without_ray_the_module_says_how_to_install_it(monkeypatch):
    import splatgl.ray as sr
    monkeypatch.setitem(sys.modules, "ray", None)
    with pytest.raises(ImportError, match=r"splatgl\[ray\]"):
        sr._ray()


def test_save_image_writes_what_compare_reads(tmp_path):
    img = np.random.default_rng(3).uniform(0, 1, (6, 5, 4)).astype(np.float32)
    splatgl.save_image(img, tmp_path / "x.pfm")
    splatgl.save_image(img, tmp_path / "x.png")
    assert splatgl.compare(tmp_path / "x.png", img)["max_abs"] <= 0.5 / 255 + 1e-6
    assert splatgl.compare(tmp_path / "x.pfm", img[..., :3])["max_abs"] == 0.0
    with pytest.raises(ValueError, match=r"\.png or \.pfm"):
        splatgl.save_image(img, tmp_path / "x.jpg")


def big_ply(tmp_path, n=6000):
    rng = np.random.default_rng(7)
    q = rng.normal(size=(n, 4))
    c = splatgl.Cloud.from_arrays(
        rng.normal(0, 2, (n, 3)), rng.uniform(0.01, 0.1, (n, 3)),
        q / np.linalg.norm(q, axis=1, keepdims=True), rng.uniform(0.2, 1, n),
        sh=rng.normal(0, 0.3, (n, 4, 3)))
    p = tmp_path / "big.ply"
    splatgl.save(c, p)
    return p


def files_of(d):
    out = {}
    for root, _, names in os.walk(d):
        for n in names:
            p = os.path.join(root, n)
            with open(p, "rb") as f:
                out[os.path.relpath(p, d)] = f.read()
    return out


def convert_streamed(src, out, scratch):
    argv = ["splatgl", "convert", str(src), str(out / "tileset.json"), "--chunk-splats", "256",
            "--scratch-dir", str(scratch), "--bucket-splats", "700"]
    assert splatgl._splatgl.cli(argv) == 0
    return files_of(out)


def test_a_distributed_build_writes_the_streamed_builds_tileset_byte_for_byte(cluster, tmp_path):
    import splatgl.tiles
    src = big_ply(tmp_path)
    want = convert_streamed(src, tmp_path / "one", tmp_path / "s1")
    seen = []
    s = splatgl.tiles.build_distributed(src, tmp_path / "many", scratch_dir=tmp_path / "s2",
                                        bucket_splats=700, chunk_splats=256,
                                        progress=lambda *a: seen.append(a))
    assert files_of(tmp_path / "many") == want and "tileset.json" in want
    assert s["splats"] == 6000 and s["buckets"] == 9 and s["ranges"] == 2
    assert s["tiles"] == len(want) - 1 and len(s["workers"]) >= 1
    assert ("building", 9, 9) in seen and ("routing", 2, 2) in seen
    assert os.listdir(tmp_path / "s2") == []


def test_a_worker_killed_mid_build_is_retried_and_the_tileset_is_the_same(cluster, tmp_path):
    import splatgl.tiles
    src = big_ply(tmp_path)
    want = convert_streamed(src, tmp_path / "one", tmp_path / "s1")
    marker = cluster
    os.makedirs(os.path.dirname(marker))  # armed: the next step's worker dies once
    try:
        s = splatgl.tiles.build_distributed(src, tmp_path / "many", scratch_dir=tmp_path / "s2",
                                            bucket_splats=700, chunk_splats=256,
                                            progress=lambda *a: None)
    finally:
        fired = os.path.exists(marker)
        shutil.rmtree(os.path.dirname(marker))
    assert fired, "no worker was killed"
    assert files_of(tmp_path / "many") == want
    assert s["splats"] == 6000


def test_a_step_given_a_wrong_plan_raises_the_tiles_error(tmp_path):
    import splatgl.tiles
    with pytest.raises(splatgl.tiles.TilesError, match="not a build plan"):
        splatgl._splatgl.tiles_route("{}", 0)
    with pytest.raises(splatgl.tiles.TilesError, match="binary PLY"):
        splatgl._splatgl.tiles_plan(str(tmp_path / "none.ply"), str(tmp_path / "t.json"),
                                    str(tmp_path / "s"), 1000, 256, 2)


def test_the_distributed_build_without_ray_says_to_install_the_extra(monkeypatch, tmp_path):
    import splatgl.tiles
    monkeypatch.setitem(sys.modules, "ray", None)
    with pytest.raises(ImportError, match=r"splatgl\[ray\]"):
        splatgl.tiles.build_distributed(tmp_path / "x.ply", tmp_path, scratch_dir=tmp_path)
