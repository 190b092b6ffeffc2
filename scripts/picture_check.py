"""Checks that terminal pictures drawn by scripts/ansi_to_svg.py render in a browser as
the terminal showed them.

    python scripts/picture_check.py [--png-dir DIR] [--font FAMILY] [--max N] [--port PORT] SVG...

Each SVG is loaded in headless Chromium (driven through the DevTools protocol) and
compared with the plain text of the same capture, the .txt beside it (SVG with .txt for
.svg). From the layout Chromium made (the SVG DOM's getStartPositionOfChar and
getExtentOfChar for every character of every <text>), the character grid is built again
as rendered: each glyph goes into the row and column its start falls in (the nearest
cell edge). That grid is compared with the text line by line, trailing spaces ignored.
A picture fails when a character is missing or another stands in its cell, when a glyph
starts more than POSITION_TOLERANCE from its cell's edge, when two glyphs land in one
cell, or when a glyph is more than WIDTH_TOLERANCE wider than a cell (its advance, in the
font Chromium picked, from getExtentOfChar).

A PNG of each rendered picture is written to DIR (target/pictures unless set) under the
SVG's name, for a person to look at. --font FAMILY renders with that font instead of the
SVG's own list, as a viewer that lacks DejaVu Sans Mono would (e.g. "Liberation Mono").

Exit status 0 with one line per picture when all match; 1 naming the picture, row,
column (both counted from 1), expected and rendered character of each mismatch (the
first N of a picture, 20 unless --max says); 2 when a picture or its text cannot be read or
Chromium cannot be driven.
"""

import argparse
import base64
import json
import os
import pathlib
import re
import sys
import time

sys.dont_write_bytecode = True  # no __pycache__ left in scripts/ by the import below
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from ansi_to_svg import BASELINE, CELL_H, CELL_W, TOP, width  # noqa: E402  the grid drawn
from devtools import Browser, DevToolsError  # noqa: E402

# A glyph's start may be this far from its cell's left edge. The converter places every
# character exactly (to a tenth of a pixel), so anything more means the browser moved it
# (stretching, collapsed spaces, a run laid out from its first character); an eighth of a
# cell (about 1 px) is where a shift starts to show against the column above and below,
# which box borders make plain.
POSITION_TOLERANCE = CELL_W / 8
# A glyph's advance may be this much wider than a cell. Monospace fonts' advances lie
# between 0.55 and 0.62 em (Consolas, Menlo, DejaVu Sans Mono, Liberation Mono, Courier),
# so within 3% of the 0.602 em cell; a glyph a fifth wider still keeps its ink inside its
# cell and its neighbour's side bearing, while one from a proportional fallback font
# (a check mark, a wide letter) is a third or more wider and runs into the next character.
WIDTH_TOLERANCE = 0.2

# Every character of every <text> with where Chromium drew it: [char, start x, baseline y,
# extent width, the element's y, the character's place in it, the element's text]; the
# positions are null for a character the browser did not lay out (e.g. a space it
# collapsed). SVG counts characters in UTF-16 code units, hence the index.
LAYOUT_JS = r"""
(() => {
  const out = [];
  for (const t of document.querySelectorAll('text')) {
    const n = t.getNumberOfChars();
    const s = t.textContent;
    const y = t.y.baseVal.length ? t.y.baseVal[0].value : 0;
    let i = 0, k = 0;
    for (const ch of s) {
      if (i >= n) {
        out.push([ch, null, null, null, y, k, s]);
      } else {
        const p = t.getStartPositionOfChar(i);
        out.push([ch, p.x, p.y, t.getExtentOfChar(i).width, y, k, s]);
      }
      i += ch.length;
      k += 1;
    }
  }
  return JSON.stringify(out);
})()
"""


class Failure(Exception):
    """A file could not be read or Chromium could not render it (exit status 2)."""


def expected_grid(text):
    """The text's rows as {column: character}, wide characters at their first column."""
    rows = []
    for line in text.split("\n"):
        row, column = {}, 0
        for ch in line.rstrip():
            if ch != " ":
                row[column] = ch
            column += width(ch)
        rows.append(row)
    while rows and not rows[-1]:
        rows.pop()
    return rows


def rendered_grid(layout):
    """The glyphs as Chromium laid them out, put into cells: ({(row, column): character},
    problems), the problems as (row, column, message) for glyphs not drawn, out of their
    cell, too wide, or sharing a cell."""
    grid, problems = {}, []
    for ch, x, y, extent_w, element_y, place, element_text in layout:
        if ch == " ":
            continue
        if x is None:
            row = round((element_y - TOP - BASELINE) / CELL_H)
            problems.append((row, None, f"{ch!r} is not laid out (the browser dropped it): "
                             f"character {place + 1} of <text> {element_text!r}"))
            continue
        column = round(x / CELL_W)
        row = round((y - TOP - BASELINE) / CELL_H)
        cell = (row, column)
        dx, dy = x - column * CELL_W, y - (TOP + row * CELL_H + BASELINE)
        if abs(dx) > POSITION_TOLERANCE or abs(dy) > CELL_H / 4:
            problems.append((row, column, f"{ch!r} is out of its cell: it starts "
                             f"{dx:+.1f} px across and {dy:+.1f} px down from the cell's origin"))
        limit = width(ch) * CELL_W * (1 + WIDTH_TOLERANCE)
        if extent_w is not None and extent_w > limit:
            problems.append((row, column, f"{ch!r} is {extent_w:.1f} px wide, more than "
                             f"{limit:.1f} px (its cells and {WIDTH_TOLERANCE:.0%})"))
        if extent_w is not None and extent_w < 0.5:
            problems.append((row, column, f"{ch!r} is drawn with no width"))
        if cell in grid:
            problems.append((row, column, f"{ch!r} and {grid[cell]!r} both land in this cell"))
        grid[cell] = ch
    return grid, problems


def compare(expected, grid):
    """Mismatches between the text and the rendered grid as (row, column, message)."""
    mismatches = []
    rows = max([len(expected)] + [r + 1 for r, _ in grid])
    for r in range(rows):
        want = expected[r] if r < len(expected) else {}
        got = {c: ch for (gr, c), ch in grid.items() if gr == r}
        for c in sorted(set(want) | set(got)):
            w, g = want.get(c, " "), got.get(c, " ")
            if w == g:
                continue
            if g == " ":
                message = f"expected {w!r}, rendered nothing (glyph missing or moved away)"
            elif w == " ":
                message = f"expected a space, rendered {g!r} (a glyph moved here)"
            else:
                message = f"expected {w!r}, rendered {g!r}"
            mismatches.append((r, c, message))
    return mismatches


def svg_size(svg_text, name):
    m = re.search(r'<svg[^>]*\bwidth="([\d.]+)"[^>]*\bheight="([\d.]+)"', svg_text)
    if not m:
        raise Failure(f"{name}: no width and height on its <svg> element")
    return int(float(m.group(1)) + 0.999), int(float(m.group(2)) + 0.999)


def fonts_used(page):
    """Which fonts Chromium drew the text with, as "family ×glyphs" (the DevTools CSS
    domain's platform fonts of every <text>)."""
    root = page.call("DOM.getDocument", depth=-1)["root"]["nodeId"]
    counts = {}
    for node in page.call("DOM.querySelectorAll", nodeId=root, selector="text")["nodeIds"]:
        for font in page.call("CSS.getPlatformFontsForNode", nodeId=node)["fonts"]:
            counts[font["familyName"]] = counts.get(font["familyName"], 0) + font["glyphCount"]
    return ", ".join(f"{family} ×{n}" for family, n in sorted(counts.items(), key=lambda kv: -kv[1]))


def check(page, svg_path, text_path, png_dir, font, max_reported):
    """One picture: its summary line, and its failures (empty when it matches)."""
    name = svg_path.name
    try:
        svg_text = svg_path.read_text(encoding="utf-8")
    except OSError as e:
        raise Failure(f"{svg_path}: cannot be read ({e.strerror})")
    try:
        text = text_path.read_text(encoding="utf-8")
    except OSError as e:
        raise Failure(f"{svg_path}: its terminal text {text_path} cannot be read ({e.strerror}); "
                      "scripts/screenshots.sh writes it beside the picture")
    w, h = svg_size(svg_text, name)
    page.call("Emulation.setDeviceMetricsOverride", width=w, height=h, deviceScaleFactor=1,
              mobile=False)
    page.call("Page.navigate", url=svg_path.resolve().as_uri())
    deadline = time.time() + 30
    while page.evaluate("document.readyState") != "complete":
        if time.time() > deadline:
            raise Failure(f"{name}: Chromium did not finish loading it in 30 s")
        time.sleep(0.1)
    if font:
        page.evaluate("for (const e of document.querySelectorAll('[font-family]')) "
                      f"e.setAttribute('font-family', {json.dumps(font)}); 0")
    page.evaluate("document.fonts ? document.fonts.ready.then(() => 0) : 0")
    if page.evaluate("document.querySelectorAll('parsererror').length"):
        raise Failure(f"{name}: Chromium could not parse it as XML")
    layout = json.loads(page.evaluate(LAYOUT_JS))
    fonts = fonts_used(page)
    png = png_dir / (svg_path.stem + ".png")
    shot = page.call("Page.captureScreenshot", format="png",
                     clip={"x": 0, "y": 0, "width": w, "height": h, "scale": 1})
    png.write_bytes(base64.b64decode(shot["data"]))

    expected = expected_grid(text)
    grid, problems = rendered_grid(layout)
    failures = problems + compare(expected, grid)
    failures.sort(key=lambda f: (f[0], -1 if f[1] is None else f[1]))
    glyphs = sum(len(r) for r in expected)
    summary = (f"{name}: {len(expected)} rows, {glyphs} glyphs "
               f"{'in their cells' if not failures else 'checked'}; fonts {fonts}; "
               f"rendered {png}")
    lines = []
    for row, column, message in failures[:max_reported]:
        where = f"row {row + 1}" + (f", column {column + 1}" if column is not None else "")
        lines.append(f"{name}: {where}: {message}")
    if len(failures) > max_reported:
        lines.append(f"{name}: … and {len(failures) - max_reported} more")
    return summary, lines


def main():
    parser = argparse.ArgumentParser(
        description="Render terminal pictures (SVG) in headless Chromium and compare each "
        "with its terminal text (.txt beside it).")
    parser.add_argument("svg", nargs="+", type=pathlib.Path)
    parser.add_argument("--png-dir", type=pathlib.Path, default=pathlib.Path("target/pictures"),
                        help="where the PNGs of the rendered pictures go (target/pictures)")
    parser.add_argument("--font", help="render with this font family instead of the SVG's")
    parser.add_argument("--max", type=int, default=20, help="mismatches shown per picture (20)")
    parser.add_argument("--port", type=int, default=9334, help="Chromium's DevTools port")
    args = parser.parse_args()
    args.png_dir.mkdir(parents=True, exist_ok=True)
    failed = False
    try:
        with Browser(args.port, ["--hide-scrollbars"]) as page:
            page.call("Page.enable")
            page.call("DOM.enable")
            page.call("CSS.enable")
            for svg_path in args.svg:
                summary, lines = check(page, svg_path, svg_path.with_suffix(".txt"),
                                       args.png_dir, args.font, args.max)
                print(summary)
                for line in lines:
                    print(line)
                failed = failed or bool(lines)
    except (Failure, DevToolsError) as e:
        print(f"picture_check: {e}", file=sys.stderr)
        return 2
    if failed:
        print("picture_check: FAILED: the pictures above do not render as the terminal showed "
              "them", file=sys.stderr)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
