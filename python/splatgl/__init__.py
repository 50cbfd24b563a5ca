"""splatgl for Python: load every 3D Gaussian splat format as NumPy arrays, save them, render
exact cameras headless (GL through EGL, or the CPU reference), validate
KHR_gaussian_splatting files, and run the conformance kit.

    import splatgl
    cloud = splatgl.load("scene.ply")
    cam = splatgl.Camera.look_at(eye=(0, 0, 4), target=(0, 0, 0), width=640, height=480)
    image = splatgl.render(cloud, cam)          # (480, 640, 4) float32
    with splatgl.Renderer() as r:               # kept open: one context, one upload
        r.upload(cloud)
        images = r.render_many([cam, cam])

See docs/python.md.
"""

from ._splatgl import (
    Camera,
    CameraError,
    Cloud,
    ConformanceError,
    LoadError,
    RenderError,
    Renderer,
    SaveError,
    SplatglError,
    TilesError,
    __version__,
    compare,
    load,
    load_bytes,
    render,
    save,
    save_image,
    validate,
)
from . import conformance

__all__ = [
    "Camera",
    "CameraError",
    "Cloud",
    "ConformanceError",
    "LoadError",
    "RenderError",
    "Renderer",
    "SaveError",
    "SplatglError",
    "TilesError",
    "__version__",
    "compare",
    "conformance",
    "load",
    "load_bytes",
    "render",
    "save",
    "save_image",
    "validate",
]
