"""Batch renders and conformance runs spread over a Ray cluster (docs/scale.md).

Each Ray worker holds a `splatgl.Renderer` (one GL context, or the reference) in an actor
and renders the views of the scenes it is given: one upload per scene, every view of it from
the same context. `ray.init()` starts a local cluster unless one is running; `address=`
names a real one. Needs the `ray` extra (`pip install splatgl[ray]`); nothing else in the
package imports Ray.

    import splatgl, splatgl.ray
    cams = [splatgl.Camera.look_at(eye=(0, 0, 4), target=(0, 0, 0), width=640, height=480)]
    summary = splatgl.ray.render_views(["a.ply", "b.spz"], cams, out_dir="renders")
"""

import os
import time
from typing import Any, Callable, Dict, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np

from . import _splatgl

PathLike = Union[str, "os.PathLike[str]"]
# A camera as it travels to a worker (splatgl.Camera is a native object Ray cannot pickle).
CameraTuple = Tuple[float, float, float, float, int, int, List[List[float]]]


def _ray():
    try:
        import ray
    except ImportError as e:  # the package works without Ray; only this module needs it
        raise ImportError(
            "splatgl.ray needs Ray: pip install 'splatgl[ray]' (or pip install ray)"
        ) from e
    return ray


def _connect(address: Optional[str]):
    ray = _ray()
    if not ray.is_initialized():
        ray.init(address=address, include_dashboard=False, log_to_driver=False)
    return ray


def _pack(cam: "_splatgl.Camera") -> CameraTuple:
    return (cam.fx, cam.fy, cam.cx, cam.cy, cam.width, cam.height, cam.world_to_camera.tolist())


def _unpack(t: CameraTuple) -> "_splatgl.Camera":
    fx, fy, cx, cy, w, h, m = t
    return _splatgl.Camera(fx, fy, cx, cy, w, h, np.array(m))


class _Worker:
    """The actor: a Renderer made on first use in the worker's own thread (GL contexts belong
    to one thread), kept for every scene the worker is given."""

    def __init__(self, backend: str, size: Optional[Tuple[int, int]]):
        self.backend, self.size, self.renderer = backend, size, None

    def render_scene(self, scene: str, cams: List[CameraTuple], out_dir: Optional[str],
                     options: Dict[str, Any]) -> Dict[str, Any]:
        start = time.perf_counter()
        if self.renderer is None:
            w, h = self.size or (None, None)
            self.renderer = _splatgl.Renderer(backend=self.backend, width=w, height=h)
        cloud = _splatgl.load(scene)
        self.renderer.upload(cloud)
        images = self.renderer.render_many([_unpack(c) for c in cams], **options)
        result = {"scene": scene, "splats": len(cloud), "backend": self.renderer.backend,
                  "worker": os.getpid()}
        if out_dir is None:
            result["images"] = images
        else:
            stem = os.path.splitext(os.path.basename(scene))[0]
            folder = os.path.join(out_dir, stem)
            os.makedirs(folder, exist_ok=True)
            paths = [os.path.join(folder, f"{i:04}.png") for i in range(len(images))]
            for img, path in zip(images, paths):
                _splatgl.save_image(img, path)
            result["images"] = paths
        result["seconds"] = time.perf_counter() - start
        return result


def render_views(
    scenes: Sequence[PathLike],
    cameras: Union[Sequence["_splatgl.Camera"], Mapping[PathLike, Sequence["_splatgl.Camera"]]],
    *,
    out_dir: Optional[PathLike] = None,
    backend: str = "auto",
    width: Optional[int] = None,
    height: Optional[int] = None,
    workers: Optional[int] = None,
    address: Optional[str] = None,
    sh_degree: int = 3,
    background: Tuple[float, float, float] = (0.0, 0.0, 0.0),
    antialiased: bool = False,
    progress: Optional[Callable[[Dict[str, Any]], None]] = None,
) -> Dict[str, Any]:
    """Renders every view of every scene on a Ray cluster: `cameras` is one list for all
    scenes or a mapping scene → list. Each of `workers` actors (default: the cluster's CPUs,
    at most one per scene) keeps a `splatgl.Renderer(backend, width, height)` and takes the
    next scene as it finishes one. With `out_dir`, image i of scene `x.ply` is written to
    `out_dir/x/0000.png` … (8-bit RGBA PNG); without it the arrays are returned. Returns a
    summary: `scenes` (per scene, in the order given: scene, splats, backend, worker pid,
    seconds, images — paths or arrays), `workers`, `views`, `wall_s`. `progress` is called
    with each scene's entry as it finishes."""
    ray = _connect(address)
    names = [os.fspath(s) for s in scenes]
    if isinstance(cameras, Mapping):
        views = {os.fspath(k): [_pack(c) for c in v] for k, v in cameras.items()}
        missing = [s for s in names if s not in views]
        if missing:
            raise ValueError(f"no cameras for {missing}")
    else:
        packed = [_pack(c) for c in cameras]
        views = {s: packed for s in names}
    if (width is None) != (height is None):
        raise ValueError("give both width and height, or neither")
    size = None if width is None else (int(width), int(height))
    options = {"sh_degree": sh_degree, "background": tuple(background), "antialiased": antialiased}
    out = None if out_dir is None else os.path.abspath(os.fspath(out_dir))
    n = workers or max(1, int(ray.cluster_resources().get("CPU", 1)))
    n = max(1, min(n, len(names)))
    # A worker that dies (a killed process, a lost node) is restarted and its scene retried.
    actor = ray.remote(num_cpus=1, max_restarts=2, max_task_retries=2)(_Worker)
    pool = [actor.remote(backend, size) for _ in range(n)]
    start = time.perf_counter()
    results: Dict[str, Dict[str, Any]] = {}
    try:
        pending = {}
        queue = list(names)
        for a in pool:
            if queue:
                s = queue.pop(0)
                pending[a.render_scene.remote(s, views[s], out, options)] = a
        while pending:
            done, _ = ray.wait(list(pending), num_returns=1)
            a = pending.pop(done[0])
            r = ray.get(done[0])
            results[r["scene"]] = r
            if progress:
                progress(r)
            if queue:
                s = queue.pop(0)
                pending[a.render_scene.remote(s, views[s], out, options)] = a
    finally:
        for a in pool:
            ray.kill(a)
    return {"scenes": [results[s] for s in names], "workers": n,
            "views": sum(len(views[s]) for s in names), "wall_s": time.perf_counter() - start}


def _grade(suite: str, images: str, out: Optional[str], input_precision: str) -> Dict[str, Any]:
    from . import conformance
    return conformance.run(suite, images, out, input_precision)


def conformance_runs(
    suite: PathLike,
    image_dirs: Sequence[PathLike],
    *,
    out_dirs: Optional[Sequence[PathLike]] = None,
    input_precision: str = "exact",
    address: Optional[str] = None,
) -> List[Dict[str, Any]]:
    """Grades many renderers' image sets against one suite in parallel on a Ray cluster (one
    task each): the reports, in the order of `image_dirs`, as `splatgl.conformance.run`
    returns them; with `out_dirs`, each report.json and report.html written there."""
    ray = _connect(address)
    if out_dirs is not None and len(out_dirs) != len(image_dirs):
        raise ValueError("out_dirs: one per image set")
    task = ray.remote(num_cpus=1, max_retries=2)(_grade)
    outs = [None] * len(image_dirs) if out_dirs is None else [os.fspath(o) for o in out_dirs]
    refs = [task.remote(os.fspath(suite), os.fspath(d), o, input_precision)
            for d, o in zip(image_dirs, outs)]
    return ray.get(refs)
