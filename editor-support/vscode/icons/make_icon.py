#!/usr/bin/python3
"""Draws icons/psys.png (the extension's 128×128 icon): the same burst as psys-file.svg.
Run: /usr/bin/python3 editor-support/vscode/icons/make_icon.py"""
import os
from PIL import Image, ImageDraw

# (x, y, r, colour) in the SVG's 16×16 units.
DOTS = [(8, 8, 2.2, "#ffb13b"), (3, 4, 1.2, "#ff7a2f"), (13, 3.5, 1.1, "#ffd34d"), (12.5, 12, 1.3, "#ff7a2f"),
        (3.5, 12.5, 1, "#ffd34d"), (8, 2, 0.8, "#ff9a3c"), (14, 8, 0.7, "#ff9a3c"), (2, 8.5, 0.7, "#ff9a3c")]
S = 4  # drawn at 4× and scaled down: smooth edges
size = 128 * S
img = Image.new("RGBA", (size, size), (0, 0, 0, 0))
d = ImageDraw.Draw(img)
d.rounded_rectangle([0, 0, size - 1, size - 1], radius=24 * S, fill="#1e1b2e")
k = size / 16
for x, y, r, c in DOTS:
    d.ellipse([(x - r) * k, (y - r) * k, (x + r) * k, (y + r) * k], fill=c)
img.resize((128, 128), Image.LANCZOS).save(os.path.join(os.path.dirname(__file__), "psys.png"))
