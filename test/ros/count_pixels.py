#!/usr/bin/env python3
"""Counts the pixels of one marker colour in a screenshot: count_pixels.py IMAGE red|blue.

The screenshot tests used ImageMagick's -fx for this, which interprets its expression once per pixel: 8 s of CPU
per 900 x 800 view, most of the rviz test's time. The same thresholds as whole-array comparisons take milliseconds.
ImageMagick still decodes the image (any format it reads), as binary PPM on stdout.

  red   the marker red (1, 0, 0), lit or not: strong red, little green and blue. Orange (1, 0.5, 0) keeps
        g/r = 0.5 and the neutral grey/blue colours have large g or b, so neither counts.
  blue  the tension blue of the forces namespace.

Prints the count; prints nothing on stdout and exits 1 when the image cannot be read.
"""
import subprocess
import sys

import numpy


def read_ppm(path):
    """The image as an H x W x 3 float array in [0, 1], decoded by ImageMagick's convert."""
    data = subprocess.run(["convert", path, "-depth", "8", "ppm:-"], check=True, capture_output=True).stdout
    # Binary PPM: "P6", width, height, maxval as whitespace-separated tokens, one whitespace, then the pixels.
    tokens, position = [], 0
    while len(tokens) < 4:
        while data[position:position + 1].isspace():
            position += 1
        if data[position:position + 1] == b"#":  # a comment runs to the end of its line
            position = data.index(b"\n", position)
            continue
        start = position
        while not data[position:position + 1].isspace():
            position += 1
        tokens.append(data[start:position])
    if tokens[0] != b"P6":
        raise ValueError("not a binary PPM")
    width, height, maxval = (int(t) for t in tokens[1:])
    pixels = numpy.frombuffer(data, dtype=numpy.uint8, count=width * height * 3, offset=position + 1)
    return pixels.reshape(height, width, 3).astype(numpy.float64) / maxval


def main():
    if len(sys.argv) != 3 or sys.argv[2] not in ("red", "blue"):
        print("usage: count_pixels.py IMAGE red|blue", file=sys.stderr)
        return 2
    try:
        image = read_ppm(sys.argv[1])
    except (OSError, ValueError, subprocess.CalledProcessError) as error:
        print(f"count_pixels.py: {sys.argv[1]}: {error}", file=sys.stderr)
        return 1
    r, g, b = image[..., 0], image[..., 1], image[..., 2]
    if sys.argv[2] == "red":
        mask = (r > 0.35) & (g < 0.12 * r + 0.02) & (b < 0.12 * r + 0.02)
    else:
        mask = (b > 0.6) & (b > r + 0.3) & (b > g + 0.2)
    print(int(numpy.count_nonzero(mask)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
