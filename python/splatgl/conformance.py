"""The KHR_gaussian_splatting conformance kit (docs/conformance.md): generate the suite,
render it with your renderer (OUT/ASSET/CAMERA.png, one per camera of each asset's
cameras.json), and grade the images."""

import json
import os
from typing import Any, Dict, Optional, Union

from . import _splatgl

PathLike = Union[str, "os.PathLike[str]"]


def generate(dir: PathLike) -> None:
    """Writes the suite into `dir`: manifest.json, assets/, reference/."""
    _splatgl.conformance_generate(os.fspath(dir))


def run(
    dir: PathLike,
    images_dir: PathLike,
    out: Optional[PathLike] = None,
    input_precision: str = "exact",
) -> Dict[str, Any]:
    """Grades the images in `images_dir` against the suite in `dir`: the report (the dict of
    report.json: passed, failed, assets, diagnosis …). With `out`, report.json and
    report.html are written there too."""
    text = _splatgl.conformance_run(
        os.fspath(dir),
        os.fspath(images_dir),
        None if out is None else os.fspath(out),
        input_precision,
    )
    return json.loads(text)
