#!/usr/bin/env python3
"""An X window dump (xwd -root, ZPixmap, 24 or 32 bits per pixel) as a PNG: the screenshot of the rviz test without
ImageMagick. Format: X11 XWDFile.h (a 100-byte big-endian header of 25 words, the window name, the colour map, then
the rows).

usage: xwd_to_png.py SCREEN.xwd SCREEN.png"""
import struct, sys
import numpy as np
from PIL import Image
data = open(sys.argv[1], "rb").read()
h = struct.unpack(">25I", data[:100])
header_size, fmt, width, height = h[0], h[2], h[4], h[5]
byte_order, bpp, bytes_per_line, ncolors = h[7], h[11], h[12], h[19]
offset = header_size + 12 * ncolors
assert fmt == 2 and bpp in (24, 32), (fmt, bpp)
step = bpp // 8
rows = np.frombuffer(data, dtype=np.uint8, count=height * bytes_per_line, offset=offset).reshape(height, bytes_per_line)
pixels = rows[:, : width * step].reshape(height, width, step)
rgb = pixels[:, :, [2, 1, 0]] if byte_order == 0 else pixels[:, :, [step - 3, step - 2, step - 1]]
Image.fromarray(np.ascontiguousarray(rgb)).save(sys.argv[2])
