"""splatgl.Renderer: a renderer kept open draws what the one-shot splatgl.render draws, with
either backend, for one camera or many, until it is closed. The GL backend needs headless
EGL: without it the GL tests skip, which fails under SPLATGL_REQUIRE=all (CI)."""

import os

import numpy as np
import pytest

import splatgl


def scene() -> splatgl.Cloud:
    rng = np.random.default_rng(7)
    n = 300
    q = rng.normal(size=(n, 4))
    return splatgl.Cloud.from_arrays(
        rng.uniform(-1, 1, (n, 3)), rng.uniform(0.02, 0.2, (n, 3)),
        q / np.linalg.norm(q, axis=1, keepdims=True), rng.uniform(0.2, 1, n),
        sh=rng.normal(0, 0.3, (n, 4, 3)))


def cameras() -> list:
    return [splatgl.Camera.look_at(eye=(np.sin(a) * 3, 0.5, np.cos(a) * 3), target=(0, 0, 0),
                                   width=48, height=36) for a in np.linspace(0, 3, 4)]


def backends() -> list:
    """The reference always; GL where headless EGL works (else a skip, a failure in CI)."""
    try:
        splatgl.Renderer(backend="gl").close()
        return ["reference", "gl"]
    except splatgl.RenderError as e:
        if os.environ.get("SPLATGL_REQUIRE") == "all":
            pytest.fail(f"no headless GL: {e} (SPLATGL_REQUIRE=all)")
        return ["reference"]


@pytest.mark.parametrize("backend", ["reference", "gl"])
def test_a_renderer_kept_open_draws_what_one_shot_render_draws(backend):
    if backend not in backends():
        pytest.skip("no headless GL")
    cloud, cams = scene(), cameras()
    with splatgl.Renderer(backend=backend) as r:
        assert r.backend == backend
        r.upload(cloud)
        for cam in cams:
            once = splatgl.render(cloud, cam, backend=backend, sh_degree=1, background=(0.1, 0.2, 0.3))
            kept = r.render(cam, sh_degree=1, background=(0.1, 0.2, 0.3))
            assert kept.shape == (36, 48, 4) and np.array_equal(once, kept)
        many = r.render_many(cams)
        assert len(many) == len(cams)
        for cam, img in zip(cams, many):
            assert np.array_equal(img, splatgl.render(cloud, cam, backend=backend))
        # A second upload replaces the first.
        half = splatgl.Cloud.from_arrays(cloud.positions[:150], cloud.scales[:150],
                                         cloud.rotations[:150], cloud.opacities[:150],
                                         sh=cloud.sh[:150])
        r.upload(half)
        assert np.array_equal(r.render(cams[0]), splatgl.render(half, cams[0], backend=backend))
    assert r.closed


def test_a_renderer_of_fixed_size_renders_every_camera_at_it():
    cloud, cam = scene(), cameras()[1]
    # Half the size: exactly halved intrinsics, the same pose (near 0.01, far 1000 as look_at).
    r = splatgl.Renderer(backend="reference", width=24, height=18)
    r.upload(cloud)
    img = r.render(cam)
    resized = splatgl.Camera(cam.fx / 2, cam.fy / 2, cam.cx / 2, cam.cy / 2, 24, 18,
                             cam.world_to_camera)
    assert img.shape == (18, 24, 4)
    assert np.array_equal(img, splatgl.render(cloud, resized, backend="reference"))
    r.close()


def test_misuse_is_an_error_not_a_crash():
    with pytest.raises(ValueError, match="backend"):
        splatgl.Renderer(backend="vulkan")
    with pytest.raises(ValueError, match="both"):
        splatgl.Renderer(width=10)
    with pytest.raises(ValueError, match="16384"):
        splatgl.Renderer(width=20000, height=10)
    r = splatgl.Renderer(backend="reference")
    with pytest.raises(splatgl.RenderError, match="upload"):
        r.render(cameras()[0])
    r.close()
    r.close()
    with pytest.raises(splatgl.RenderError, match="closed"):
        r.upload(scene())
    with pytest.raises(splatgl.RenderError, match="closed"):
        r.render(cameras()[0])
    assert "closed" in repr(r)
