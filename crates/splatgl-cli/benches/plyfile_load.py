#!/usr/bin/env python3
"""plyfile + numpy doing what `splatgl info` does: read every vertex row into memory and
convert to the cloud's arrays (exp scales, sigmoid opacity, normalised xyzw quaternions,
degree-major SH), then bounds."""
import sys, time
import numpy as np
from plyfile import PlyData
t = time.time()
v = PlyData.read(sys.argv[1])['vertex'].data
t_read = time.time() - t
pos = np.stack([v['x'], v['y'], v['z']], 1)
scale = np.exp(np.stack([v['scale_0'], v['scale_1'], v['scale_2']], 1))
op = 1 / (1 + np.exp(-v['opacity']))
q = np.stack([v['rot_1'], v['rot_2'], v['rot_3'], v['rot_0']], 1)
q /= np.linalg.norm(q, axis=1, keepdims=True)
dc = np.stack([v['f_dc_0'], v['f_dc_1'], v['f_dc_2']], 1)
rest = np.stack([v[f'f_rest_{i}'] for i in range(45)], 1).reshape(-1, 3, 15).transpose(0, 2, 1)
sh = np.concatenate([dc[:, None, :], rest], 1)
lo, hi = pos.min(0), pos.max(0)
print(len(v), f"{time.time() - t:.3f} s", lo, hi, sh.shape, scale.dtype, op.dtype, q.dtype)
