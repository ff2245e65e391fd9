"""Captions and labels on pictures (`modc render`, `modc play --record`, both engines): a caption
band along the bottom (what is shown: robot, chain, pose or time) and target labels beside
their markers. Pillow's built-in scalable font (no font file from the system), sized to the
picture so that it reads on a slide; same input, same pixels.
"""
from __future__ import annotations

CAPTION_SHARE = 0.032  # caption text height as a share of the picture height
LABEL_SHARE = 0.026
INK = (34, 38, 46)
BAND = (255, 255, 255, 200)
TARGET_INK = (170, 20, 40)


def _font(px: int):
    from PIL import ImageFont

    return ImageFont.load_default(size=max(10, px))


def band_height(height: int) -> int:
    """Pixels the caption band takes at the bottom of a picture this tall."""
    size = round(height * CAPTION_SHARE)
    return size + 2 * max(4, size // 2)


def below(img, height: int):
    """img on a white canvas `height` tall (img at the top): room for the band under the scene."""
    from PIL import Image

    canvas = Image.new("RGB", (img.width, height), (255, 255, 255))
    canvas.paste(img, (0, 0))
    return canvas


def draw(img, title: str, detail: str = "", labels=()):
    """img (PIL RGB) with a translucent band at the bottom holding `title` (bold-ish: drawn
    twice, offset a pixel) and `detail`, and labels: (text, (u, v) pixel of the marker) drawn
    beside each marker, moved down when they would overlap an earlier one."""
    from PIL import Image, ImageDraw

    img = img.convert("RGBA")
    w, h = img.size
    size = round(h * CAPTION_SHARE)
    font, small = _font(size), _font(round(size * 0.8))
    overlay = Image.new("RGBA", img.size, (0, 0, 0, 0))
    pen = ImageDraw.Draw(overlay)
    pad = max(4, size // 2)
    band_h = band_height(h)
    pen.rectangle((0, h - band_h, w, h), fill=BAND)
    x, y = pad * 2, h - band_h + pad
    pen.text((x, y), title, font=font, fill=INK)
    pen.text((x + 1, y), title, font=font, fill=INK)
    if detail:
        tw = pen.textlength(title, font=font)
        pen.text((x + tw + size * 1.5, y + size * 0.15), detail, font=small, fill=INK)
    _labels(pen, labels, _font(round(h * LABEL_SHARE)), w, h - band_h)
    return Image.alpha_composite(img, overlay).convert("RGB")


def _labels(pen, labels, font, w: int, h: int) -> None:
    placed: list[tuple[float, float, float, float]] = []
    for text, (u, v) in labels:
        if not (0 <= u < w and 0 <= v < h):
            continue  # the marker is outside the picture
        x0, y0, x1, y1 = pen.textbbox((0, 0), text, font=font)
        tw, th = x1 - x0, y1 - y0
        pad = max(2, th // 4)
        x = min(u + th * 0.8, w - tw - 2 * pad)
        y = v - th - th * 0.6
        for _ in range(len(placed) + 1):  # step down past every label it would cover
            box = (x - pad, y - pad, x + tw + pad, y + th + pad)
            hit = [b for b in placed if box[0] < b[2] and b[0] < box[2] and box[1] < b[3] and b[1] < box[3]]
            if not hit:
                break
            y = max(b[3] for b in hit) + pad
        box = (x - pad, y - pad, x + tw + pad, y + th + pad)
        pen.rectangle(box, fill=(255, 255, 255, 215), outline=TARGET_INK + (255,))
        pen.line((u, v, x - pad, y + th / 2), fill=TARGET_INK + (255,), width=max(1, th // 10))
        pen.text((x - x0, y - y0), text, font=font, fill=TARGET_INK)
        placed.append(box)
