#!/usr/bin/env python3
"""A terminal screen captured with colours (`tmux capture-pane -e -p`) as an SVG image.

Reads the capture on standard input, writes the SVG on standard output, and with
--text OUT.txt also the screen's plain text (what `tmux capture-pane -p` shows: the same
characters without the escapes, trailing spaces dropped), so that picture and text come
from the same capture. The foreground, background, bold, dim and reverse attributes of
the SGR escapes tmux emits are kept (16 colours, 256 colours and 24-bit colour).

Every character is drawn in its own cell of a fixed grid, whatever font the viewer
has: each <text> (a run of characters in one style) lists the x of every character, one
cell (CELL_W) apart, so a glyph that is narrower, wider or taken from a fallback font
cannot move the ones after it, and nothing is stretched to fit. Characters the terminal
shows two cells wide (East Asian wide and full-width) take two cells.
scripts/picture_check.py renders the SVG in Chromium and checks that every glyph landed
in its cell.
Usage: tmux capture-pane -e -p -t SESSION | python3 scripts/ansi_to_svg.py [--text OUT.txt] > screen.svg
"""

import argparse
import html
import re
import sys
import unicodedata

FONT_SIZE = 14
CELL_W = 8.43  # DejaVu Sans Mono's advance at 14 px
CELL_H = 18
TOP = 4  # the margin above the first row
BASELINE = CELL_H - 5  # a row's baseline below its top
BACKGROUND = "#1e1e1e"
FOREGROUND = "#d4d4d4"
# The 16 colours of a dark terminal theme (normal, then bright).
PALETTE16 = [
    "#000000", "#cd3131", "#0dbc79", "#e5e510", "#2472c8", "#bc3fbc", "#11a8cd", "#e5e5e5",
    "#666666", "#f14c4c", "#23d18b", "#f5f543", "#3b8eea", "#d670d6", "#29b8db", "#ffffff",
]
SGR = re.compile(r"\x1b\[([0-9;:]*)m")
OTHER_ESCAPE = re.compile(r"\x1b(\[[0-9;?]*[A-Za-z]|\][^\x07]*\x07|[()][A-Z0-9])")


def colour256(n):
    if n < 16:
        return PALETTE16[n]
    if n < 232:
        n -= 16
        steps = [0, 95, 135, 175, 215, 255]
        return "#%02x%02x%02x" % (steps[n // 36], steps[(n // 6) % 6], steps[n % 6])
    level = 8 + 10 * (n - 232)
    return "#%02x%02x%02x" % (level, level, level)


class Style:
    def __init__(self):
        self.reset()

    def reset(self):
        self.fg = None
        self.bg = None
        self.bold = False
        self.dim = False
        self.reverse = False

    def apply(self, params):
        codes = [int(p) if p else 0 for p in re.split("[;:]", params)] if params else [0]
        i = 0
        while i < len(codes):
            c = codes[i]
            if c == 0:
                self.reset()
            elif c == 1:
                self.bold = True
            elif c == 2:
                self.dim = True
            elif c == 22:
                self.bold = self.dim = False
            elif c == 7:
                self.reverse = True
            elif c == 27:
                self.reverse = False
            elif 30 <= c <= 37:
                self.fg = PALETTE16[c - 30]
            elif 90 <= c <= 97:
                self.fg = PALETTE16[c - 90 + 8]
            elif c == 39:
                self.fg = None
            elif 40 <= c <= 47:
                self.bg = PALETTE16[c - 40]
            elif 100 <= c <= 107:
                self.bg = PALETTE16[c - 100 + 8]
            elif c == 49:
                self.bg = None
            elif c in (38, 48) and i + 1 < len(codes):
                if codes[i + 1] == 5 and i + 2 < len(codes):
                    value = colour256(codes[i + 2])
                    i += 2
                elif codes[i + 1] == 2 and i + 4 < len(codes):
                    value = "#%02x%02x%02x" % tuple(codes[i + 2 : i + 5])
                    i += 4
                else:
                    value = None
                if c == 38:
                    self.fg = value
                else:
                    self.bg = value
            i += 1

    def colours(self):
        fg, bg = self.fg or FOREGROUND, self.bg
        if self.reverse:
            fg, bg = bg or BACKGROUND, fg
        return fg, bg

    def key(self):
        return self.colours() + (self.bold, self.dim)


def width(char):
    """How many cells the terminal gives the character: two for wide ones."""
    return 2 if unicodedata.east_asian_width(char) in ("W", "F") else 1


def cells(line):
    """The line's characters, each with its style's key and its first column."""
    style = Style()
    out = []
    pos = 0
    column = 0
    while pos < len(line):
        m = SGR.match(line, pos)
        if m:
            style.apply(m.group(1))
            pos = m.end()
            continue
        m = OTHER_ESCAPE.match(line, pos)
        if m:
            pos = m.end()
            continue
        out.append((line[pos], style.key(), column))
        column += width(line[pos])
        pos += 1
    return out


def plain_text(lines):
    """The screen's characters without the escapes, one line per row."""
    return "".join("".join(c for c, _, _ in cells(l)).rstrip() + "\n" for l in lines)


def coordinate(value):
    """A coordinate with at most one decimal (a tenth of a pixel is below what shows)."""
    return ("%.1f" % value).removesuffix(".0")


def text_runs(row):
    """The row's text elements as (style key, cells): runs of one style, split where two
    or more spaces come, without leading or trailing spaces. So no element holds a space
    that a viewer collapsing white space (one that ignores xml:space) would drop, which
    would give the characters after it the positions of others."""
    runs = []
    i = 0
    while i < len(row):
        key = row[i][1]
        end = i
        while end < len(row) and row[end][1] == key:
            end += 1
        drawn = [j for j in range(i, end) if row[j][0] != " "]
        while drawn:
            last = 0
            while last + 1 < len(drawn) and drawn[last + 1] - drawn[last] <= 2:
                last += 1
            runs.append((key, row[drawn[0] : drawn[last] + 1]))
            drawn = drawn[last + 1 :]
        i = end
    return runs


def svg(lines):
    rows = [cells(l) for l in lines]
    columns = max((c[2] + width(c[0]) for r in rows for c in r[-1:]), default=0)
    w, h = columns * CELL_W, len(rows) * CELL_H
    parts = [
        f'<svg xmlns="http://www.w3.org/2000/svg" width="{w:.0f}" height="{h + 2 * TOP:.0f}" '
        f'viewBox="0 0 {w:.0f} {h + 2 * TOP:.0f}">',
        f'<rect width="100%" height="100%" fill="{BACKGROUND}"/>',
        f'<g font-family="DejaVu Sans Mono, Menlo, Consolas, monospace" '
        f'font-size="{FONT_SIZE}" xml:space="preserve" style="white-space:pre">',
    ]
    for y, row in enumerate(rows):
        top = TOP + y * CELL_H
        # Backgrounds: one rectangle per run of cells with the same colour.
        x = 0
        while x < len(row):
            bg = row[x][1][1]
            end = x
            while end < len(row) and row[end][1][1] == bg:
                end += 1
            if bg:
                left = row[x][2]
                right = row[end - 1][2] + width(row[end - 1][0])
                parts.append(
                    f'<rect x="{coordinate(left * CELL_W)}" y="{top}" '
                    f'width="{coordinate((right - left) * CELL_W)}" height="{CELL_H}" fill="{bg}"/>'
                )
            x = end
        # Text: every character placed at its own cell.
        for key, run in text_runs(row):
            fg, _, bold, dim = key
            attrs = f'fill="{fg}"'
            if bold:
                attrs += ' font-weight="bold"'
            if dim:
                attrs += ' fill-opacity="0.6"'
            xs = " ".join(coordinate(column * CELL_W) for _, _, column in run)
            text = "".join(c for c, _, _ in run)
            parts.append(
                f'<text x="{xs}" y="{top + BASELINE}" {attrs}>{html.escape(text, quote=False)}</text>'
            )
    parts.append("</g></svg>")
    return "\n".join(parts) + "\n"


def main():
    parser = argparse.ArgumentParser(
        description="A coloured terminal capture (stdin) as an SVG image (stdout)."
    )
    parser.add_argument("--text", metavar="OUT.txt", help="also write the screen's plain text here")
    args = parser.parse_args()
    lines = sys.stdin.read().split("\n")
    while lines and not lines[-1].strip():
        lines.pop()
    if args.text:
        with open(args.text, "w", encoding="utf-8") as f:
            f.write(plain_text(lines))
    sys.stdout.write(svg(lines))


if __name__ == "__main__":
    main()
