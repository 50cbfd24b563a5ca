"""LOD tilesets built on a Ray cluster (docs/scale.md): the bucketed build of
`splatgl convert big.ply out/tileset.json --scratch-dir D` cut into steps that workers share.

1. plan (driver): one pass samples the means and places the bucket planes;
2. route (a task per row range, in parallel): each splat to its bucket's part file;
3. build (a task per bucket, in parallel): the bucket's subtree and its tiles' .glb files;
4. join (driver): the tiles above the buckets, then tileset.json.

The result is byte for byte the tileset `convert … --scratch-dir D --bucket-splats B`
writes with the same bucket size. Every worker must reach `input`, `scratch_dir` and
`out_dir` at the same paths: one machine's disk for a local cluster, a shared file system
(NFS, a mounted bucket) for a real one. A task whose worker dies is run again (each step
writes its files whole or not at all, so a retry writes the same bytes).

    import splatgl.tiles
    summary = splatgl.tiles.build_distributed("big.ply", "out", scratch_dir="/shared/scratch")

Needs the `ray` extra (`pip install 'splatgl[ray]'`); nothing else in the package imports Ray.
"""

import json
import os
import resource
import time
from typing import Any, Callable, Dict, List, Optional, Union

from . import _splatgl

PathLike = Union[str, "os.PathLike[str]"]

#: At most this many splats per tile (as `convert --chunk-splats`).
DEFAULT_CHUNK_SPLATS: int = _splatgl.TILE_CHUNK_SPLATS
#: About this many splats per bucket: what one worker builds in memory at once.
DEFAULT_BUCKET_SPLATS: int = _splatgl.TILE_BUCKET_SPLATS
#: The error a step raises.
TilesError = _splatgl.TilesError

# Tests only: the path of a marker file; once its folder exists, the first step that finds the
# file missing creates it and kills its own worker process (a worker lost mid-build), so the
# retry path is exercised.
_KILL_ONCE = "SPLATGL_TEST_KILL_ONCE"


def _peak_mb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def _maybe_die() -> None:
    marker = os.environ.get(_KILL_ONCE)
    if marker:
        try:  # armed when the marker's folder exists; fired once
            fd = os.open(marker, os.O_CREAT | os.O_EXCL | os.O_WRONLY)
        except OSError:
            return
        os.close(fd)
        os._exit(1)


def _route(plan: str, i: int) -> Dict[str, Any]:
    _maybe_die()
    start = time.perf_counter()
    r = json.loads(_splatgl.tiles_route(plan, i))
    r.update(seconds=time.perf_counter() - start, worker=os.getpid(), peak_mb=_peak_mb())
    return r


def _build(plan: str, b: int) -> Dict[str, Any]:
    _maybe_die()
    start = time.perf_counter()
    text = _splatgl.tiles_build_bucket(plan, b)
    return {"report": text, "seconds": time.perf_counter() - start, "worker": os.getpid(),
            "peak_mb": _peak_mb()}


def _ray():
    try:
        import ray
    except ImportError as e:
        raise ImportError(
            "splatgl.tiles.build_distributed needs Ray: pip install 'splatgl[ray]' "
            "(or pip install ray)"
        ) from e
    return ray


def build_distributed(
    input: PathLike,
    out_dir: PathLike,
    *,
    scratch_dir: PathLike,
    bucket_splats: int = DEFAULT_BUCKET_SPLATS,
    chunk_splats: int = DEFAULT_CHUNK_SPLATS,
    ranges: Optional[int] = None,
    address: Optional[str] = None,
    max_retries: int = 3,
    progress: Optional[Callable[[str, int, int], None]] = None,
) -> Dict[str, Any]:
    """Builds `out_dir/tileset.json` and `out_dir/tiles/*.glb` from the binary PLY `input` on
    a Ray cluster (`ray.init()` local unless one is running; `address` names a real one).
    `scratch_dir` holds the buckets' files (about the input's size; removed at the end);
    `bucket_splats` is the work of one build task, `chunk_splats` the splats per tile;
    `ranges` cuts the input for routing (default: the cluster's CPUs). `progress(stage, done,
    total)` is called as ranges and buckets finish (default: a line on stderr per step).
    Returns a summary: tileset, splats, tiles, bytes, buckets, ranges, largest_bucket,
    scratch_bytes, bytes_to_workers / bytes_from_workers (what Ray carried), driver_peak_mb,
    workers (pid → peak_mb, tasks), seconds per stage, findings and notes. Raises
    `TilesError` with the step's message; a task is retried `max_retries` times if its
    worker dies."""
    ray = _ray()
    if not ray.is_initialized():
        ray.init(address=address, include_dashboard=False, log_to_driver=False)
    out = os.path.abspath(os.fspath(out_dir))
    os.makedirs(out, exist_ok=True)
    say = progress or _stderr_progress
    n = ranges or max(1, int(ray.cluster_resources().get("CPU", 1)))
    t0 = time.perf_counter()
    plan = _splatgl.tiles_plan(os.path.abspath(os.fspath(input)),
                               os.path.join(out, "tileset.json"),
                               os.path.abspath(os.fspath(scratch_dir)),
                               bucket_splats, chunk_splats, n)
    p = json.loads(plan)
    seconds = {"plan": time.perf_counter() - t0}
    moved = [0, 0]
    try:
        routes = _run(ray, _route, plan, len(p["ranges"]), max_retries, "routing", say, moved)
        seconds["route"] = time.perf_counter() - t0 - seconds["plan"]
        builds = _run(ray, _build, plan, p["buckets"], max_retries, "building", say, moved)
        seconds["build"] = time.perf_counter() - t0 - seconds["plan"] - seconds["route"]
        reports = [b["report"] for b in builds]
        joined = json.loads(_splatgl.tiles_join(plan, reports))
    except BaseException:
        _remove_scratch(p)
        raise
    seconds["join"] = time.perf_counter() - t0 - sum(seconds.values())
    seconds["total"] = time.perf_counter() - t0
    return _summary(p, routes, builds, joined, seconds, moved)


def _stderr_progress(stage: str, done: int, total: int) -> None:
    import sys
    print(f"splatgl.tiles: {stage} {done}/{total}", file=sys.stderr, flush=True)


def _run(ray, fn, plan: str, count: int, retries: int, stage: str,
         say: Callable[[str, int, int], None], moved: List[int]) -> List[Dict[str, Any]]:
    """Runs fn(plan, i) for every i on the cluster; results in order of i."""
    task = ray.remote(num_cpus=1, max_retries=retries)(fn)
    plan_ref = ray.put(plan)
    refs = [task.remote(plan_ref, i) for i in range(count)]
    moved[0] += len(plan) + 8 * count
    index = {r: i for i, r in enumerate(refs)}
    results: List[Any] = [None] * count
    pending = list(refs)
    while pending:
        done, pending = ray.wait(pending, num_returns=1)
        r = ray.get(done[0])
        moved[1] += len(json.dumps(r))
        results[index[done[0]]] = r
        say(stage, count - len(pending), count)
    return results


def _remove_scratch(p: Dict[str, Any]) -> None:
    d = p["scratch_dir"]
    for name in os.listdir(d) if os.path.isdir(d) else []:
        if name.startswith(("part-", "coarse-")) or name == "plan.json":
            try:
                os.remove(os.path.join(d, name))
            except OSError:
                pass


def _summary(p, routes, builds, joined, seconds, moved) -> Dict[str, Any]:
    workers: Dict[int, Dict[str, Any]] = {}
    for r in routes + builds:
        w = workers.setdefault(r["worker"], {"peak_mb": 0.0, "tasks": 0})
        w["peak_mb"] = max(w["peak_mb"], r["peak_mb"])
        w["tasks"] += 1
    buckets = [json.loads(b["report"]) for b in builds]
    root = joined["root"]

    def count(t):
        return 1 + sum(count(c) for c in t["children"])

    notes = sorted({n for b in buckets for n in b["notes"]} | set(joined["notes"]))
    return {
        "tileset": p["output"], "splats": joined["splats"], "tiles": count(root),
        "bytes": joined["bytes"] + sum(b["bytes"] for b in buckets),
        "buckets": p["buckets"], "ranges": len(p["ranges"]),
        "largest_bucket": max(b["splats"] for b in buckets),
        "scratch_bytes": sum(r["bytes"] for r in routes),
        "bytes_to_workers": moved[0], "bytes_from_workers": moved[1],
        "driver_peak_mb": _peak_mb(), "workers": workers, "seconds": seconds,
        "findings": [f for r in routes for f in r["findings"]], "notes": notes,
    }
