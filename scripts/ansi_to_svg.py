#!/usr/bin/env python3
"""A terminal screen captured with colours (`tmux capture-pane -e -p`) as an SVG image.

Reads the capture on standard input, writes the SVG on standard output. Each character
cell is drawn at a fixed advance in a monospace font, with the foreground, background,
bold and reverse attributes of the SGR escapes tmux emits (16 colours, 256 colours and
24-bit colour).
Usage: tmux capture-pane -e -p -t SESSION | python3 scripts/ansi_to_svg.py > screen.svg
"""

import html
import re
import sys

FONT_SIZE = 14
CELL_W = 8.43  # DejaVu Sans Mono's advance at 14 px
CELL_H = 18
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


def cells(line):
    """The line's characters, each with its style's key."""
    style = Style()
    out = []
    pos = 0
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
        out.append((line[pos], style.key()))
        pos += 1
    return out


def svg(lines):
    rows = [cells(l) for l in lines]
    width = max((len(r) for r in rows), default=0)
    w, h = width * CELL_W, len(rows) * CELL_H
    parts = [
        f'<svg xmlns="http://www.w3.org/2000/svg" width="{w:.0f}" height="{h + 8:.0f}" '
        f'viewBox="0 0 {w:.0f} {h + 8:.0f}">',
        f'<rect width="100%" height="100%" fill="{BACKGROUND}"/>',
        f'<g font-family="DejaVu Sans Mono, Menlo, Consolas, monospace" '
        f'font-size="{FONT_SIZE}" xml:space="preserve">',
    ]
    for y, row in enumerate(rows):
        top = 4 + y * CELL_H
        # Backgrounds: one rectangle per run of cells with the same colour.
        x = 0
        while x < len(row):
            bg = row[x][1][1]
            end = x
            while end < len(row) and row[end][1][1] == bg:
                end += 1
            if bg:
                parts.append(
                    f'<rect x="{x * CELL_W:.2f}" y="{top}" width="{(end - x) * CELL_W:.2f}" '
                    f'height="{CELL_H}" fill="{bg}"/>'
                )
            x = end
        # Text: one element per run of the same style, placed at its first cell so that
        # wide or missing glyphs cannot shift what follows.
        x = 0
        while x < len(row):
            key = row[x][1]
            end = x
            while end < len(row) and row[end][1] == key:
                end += 1
            text = "".join(c for c, _ in row[x:end])
            if text.strip():
                fg, _, bold, dim = key
                attrs = f'fill="{fg}"'
                if bold:
                    attrs += ' font-weight="bold"'
                if dim:
                    attrs += ' fill-opacity="0.6"'
                parts.append(
                    f'<text x="{x * CELL_W:.2f}" y="{top + CELL_H - 5}" '
                    f'textLength="{(end - x) * CELL_W:.2f}" lengthAdjust="spacingAndGlyphs" '
                    f"{attrs}>{html.escape(text)}</text>"
                )
            x = end
    parts.append("</g></svg>")
    return "\n".join(parts) + "\n"


def main():
    lines = sys.stdin.read().split("\n")
    while lines and not lines[-1].strip():
        lines.pop()
    sys.stdout.write(svg(lines))


if __name__ == "__main__":
    main()
