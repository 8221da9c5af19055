#!/usr/bin/python3
"""Draws editor-support/vscode/images/preview.png: a .psys file as VS Code's Dark+ theme colours
our TextMate grammar's scopes, with the diagnostic `psysc lsp` publishes for it
underlined and its message shown as the editor's hover shows it. It is drawn from the
real tokens and the real diagnostic, not captured from a running VS Code.

Run from the repository root after building:
    /usr/bin/python3 editor-support/vscode/scripts/preview.py build/tools/psysc/psysc"""
import json
import os
import subprocess
import sys
import tempfile

from PIL import Image, ImageDraw, ImageFont

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.join(HERE, "..", "..", "..")
sys.path.insert(0, os.path.join(ROOT, "tests", "lsp"))
from lsp_client import Client  # noqa: E402

# Dark+ (VS Code's default dark theme): the first prefix that matches a token's innermost scope wins.
THEME = [
    ("comment", "#6A9955"), ("string", "#CE9178"), ("constant.numeric", "#B5CEA8"),
    ("constant.language", "#569CD6"), ("storage.type", "#569CD6"), ("keyword.control", "#C586C0"),
    ("keyword.operator", "#D4D4D4"), ("entity.name.type", "#4EC9B0"), ("support.type", "#4EC9B0"),
    ("entity.name.function", "#DCDCAA"), ("support.function", "#DCDCAA"), ("support.constant", "#4FC1FF"),
    ("variable.other.constant", "#4FC1FF"), ("variable.language", "#569CD6"), ("variable.parameter", "#9CDCFE"),
    ("entity.other.attribute-name", "#9CDCFE"), ("variable", "#9CDCFE"),
]
DEFAULT = "#D4D4D4"

TEXT = """extern sparks: float = 50;

fn gravity(m: float) -> vec3 = vec3(0, -9.82 * m, 0);

@integrator(rk4)
object spark(ipos: vec3) {
    pos = snapshot(ipos) + integrate(vel);
    vel = origin + integrate(acc);
    acc = gravity(0.4) + wind;
    point(pos, mix(green, black, age), 2);
    kill when age > 1;
}
"""


def colour(scopes):
    for scope in reversed(scopes):
        for prefix, c in THEME:
            if scope.startswith(prefix):
                return c
    return DEFAULT


def main(psysc):
    work = tempfile.mkdtemp()
    path = os.path.join(work, "sparks.psys")
    with open(path, "w") as f:
        f.write(TEXT)
    lines = json.loads(subprocess.check_output(["node", os.path.join(HERE, "tokens.js"), path]))
    client = Client(psysc)
    client.request("initialize", {"capabilities": {}})
    uri = "file://" + path
    client.notify("textDocument/didOpen", {"textDocument": {"uri": uri, "languageId": "psys", "version": 1, "text": TEXT}})
    diagnostics = client.diagnostics(uri)["diagnostics"]
    client.request("shutdown")
    client.notify("exit", {})

    font = ImageFont.truetype("/usr/share/fonts/truetype/dejavu/DejaVuSansMono.ttf", 15)
    cw, lh, left, top = font.getlength("m"), 22, 56, 16
    width, height = int(left + 72 * cw), top + lh * (len(lines) + 1)
    img = Image.new("RGB", (width, height), "#1E1E1E")
    d = ImageDraw.Draw(img)
    for i, tokens in enumerate(lines):
        y = top + i * lh
        d.text((12, y), f"{i + 1:>3}", font=font, fill="#858585")
        for t in tokens:
            d.text((left + t["start"] * cw, y), t["text"], font=font, fill=colour(t["scopes"]))
    for diag in diagnostics:  # a red squiggle under the range, the message below as a hover box
        r = diag["range"]
        y = top + r["start"]["line"] * lh + lh - 4
        x0, x1 = left + r["start"]["character"] * cw, left + r["end"]["character"] * cw
        for x in range(int(x0), int(x1), 4):
            d.line([(x, y), (x + 2, y + 2), (x + 4, y)], fill="#F14C4C", width=1)
        box_x, box_y = x1 + 24, y - lh - 2  # beside the line, as the hover over the squiggle
        message = diag["message"] + "  psysc"
        box_w = font.getlength(message) + 20
        d.rectangle([box_x, box_y, box_x + box_w, box_y + lh + 8], fill="#252526", outline="#454545")
        d.text((box_x + 10, box_y + 5), message, font=font, fill="#CCCCCC")
    out = os.path.join(HERE, "..", "images", "preview.png")
    img.save(out)
    print(out, [d["message"] for d in diagnostics])


if __name__ == "__main__":
    main(sys.argv[1])
