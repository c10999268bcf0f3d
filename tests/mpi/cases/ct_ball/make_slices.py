#!/usr/bin/python3
"""Writes the 16 slices ct_001.png .. ct_016.png of a scanned ball with a cavity (16 x 16 pixels
each): level 200 in the shell (radius 7 pixels), 100 in the cavity (radius 3), 0 outside; a voxel
takes the level of its centre. Used by tests/mpi/cases/image_stack_3d.toml; run it from this
folder to write them again."""
import numpy as np
from matplotlib import image

n = 16
c = (np.arange(n) + 0.5) - n / 2
for k in range(n):
    y, x = np.meshgrid(c, c, indexing="ij")
    r = np.sqrt(x * x + y * y + c[k] ** 2)
    level = np.where(r <= 3, 100, np.where(r <= 7, 200, 0)).astype(np.uint8)
    image.imsave(f"ct_{k + 1:03d}.png", level, cmap="gray", vmin=0, vmax=255)
