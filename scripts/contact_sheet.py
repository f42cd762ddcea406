#!/usr/bin/python3
"""Renders every bundled scene, and the example models that examples/models.cpp builds in code,
and tiles the pictures into one labelled PNG: the README's picture of the gallery
(assets/readme/gallery.png).

Needs a build (sh scripts/build.sh) and Debian's python3-pil (apt-get install python3-pil);
labels are set in DejaVu Sans (fonts-dejavu-core, which the build installs already). A
developer's script, not run by CI. Run it from the repository root after the scenes or the
renderer change:

    scripts/contact_sheet.py                     # writes assets/readme/gallery.png
    scripts/contact_sheet.py -o sheet.png --columns 5 --tile 320x240
    scripts/contact_sheet.py --examples ""       # the bundled scenes only
"""
import argparse
import json
import math
import pathlib
import subprocess
import sys
import tempfile

from PIL import Image, ImageDraw, ImageFont

ROOT = pathlib.Path(__file__).resolve().parent.parent
FONT = "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf"
# The models of examples/models.cpp (and models.py), as it names their files.
EXAMPLES = ["bracket", "gear", "vase", "lattice"]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("-o", "--output", default=str(ROOT / "assets/readme/gallery.png"))
    parser.add_argument("--scenes", default=str(ROOT / "assets/scenes"))
    parser.add_argument("--sdfcsg", default=str(ROOT / "build/apps/sdfcsg"))
    parser.add_argument("--examples", default=str(ROOT / "build/examples/sdfcsg_examples"),
                        help="the examples' program, which writes their scenes; empty: none")
    parser.add_argument("--tile", default="256x192", help="size of each picture, WxH")
    parser.add_argument("--columns", type=int, default=0,
                        help="default: a sheet about half as wide again as it is tall")
    parser.add_argument("--aa", type=int, default=2, help="samples per pixel along each axis")
    args = parser.parse_args()

    width, height = (int(v) for v in args.tile.split("x"))
    scenes = sorted(pathlib.Path(args.scenes).glob("*.json"))
    if not scenes:
        sys.exit(f"no scenes in {args.scenes}")
    with tempfile.TemporaryDirectory() as tmp:
        # The examples after the scenes, in the order the program writes them.
        examples = []
        if args.examples:
            subprocess.run([args.examples, tmp], check=True)
            examples = [pathlib.Path(tmp) / f"{name}.json" for name in EXAMPLES]
        draw_sheet(args, width, height, scenes + examples, set(examples))


def draw_sheet(args, width, height, scenes, examples):
    columns = args.columns or math.ceil(math.sqrt(1.5 * len(scenes)))
    rows = math.ceil(len(scenes) / columns)

    font = ImageFont.truetype(FONT, 14)
    label_height = 22
    sheet = Image.new("RGB", (columns * width, rows * (height + label_height)), "white")
    draw = ImageDraw.Draw(sheet)

    with tempfile.TemporaryDirectory() as tmp:
        for i, scene in enumerate(scenes):
            png = pathlib.Path(tmp) / f"{i:02}.png"
            print(f"[{i + 1}/{len(scenes)}] {scene.name}", flush=True)
            subprocess.run([args.sdfcsg, "render", str(scene), "-o", str(png),
                            "--width", str(width), "--height", str(height),
                            "--aa", str(args.aa)], check=True)
            x, y = (i % columns) * width, (i // columns) * (height + label_height)
            with Image.open(png) as picture:
                sheet.paste(picture.convert("RGB"), (x, y))
            # The scene's own title where it has one, else its file name; an example's says so.
            label = json.loads(scene.read_text()).get("name") or scene.stem
            if scene in examples:
                label = f"example: {label}"
            text_width = draw.textlength(label, font=font)
            draw.text((x + (width - text_width) / 2, y + height + 3), label, fill="black",
                      font=font)

    sheet.save(args.output, optimize=True)
    print(f"{args.output}: {columns} x {rows} tiles of {width} x {height}")


if __name__ == "__main__":
    main()
