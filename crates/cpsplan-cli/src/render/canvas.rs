//! The drawing surface: an opaque RGBA pixmap with direct, allocation-free fills for
//! rectangles and bitmap text, and anti-aliased vector drawing through tiny-skia.

use tiny_skia::{
    FillRule, LineCap, LineJoin, Paint, Path, PathBuilder, Pixmap, Stroke, StrokeDash, Transform,
};

use super::RenderError;

/// An opaque colour.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Rgb(pub u8, pub u8, pub u8);

impl Rgb {
    /// From `0xRRGGBB`.
    pub const fn hex(v: u32) -> Self {
        Self((v >> 16) as u8, (v >> 8) as u8, v as u8)
    }

    /// As CSS and SVG write it: `#rrggbb`.
    pub fn css(self) -> String {
        format!("#{:02x}{:02x}{:02x}", self.0, self.1, self.2)
    }

    /// This colour blended over `under` with opacity `alpha` (0–255).
    pub fn over(self, under: Rgb, alpha: u8) -> Rgb {
        let a = u32::from(alpha);
        let mix = |src: u8, dst: u8| {
            ((u32::from(src) * a + u32::from(dst) * (255 - a) + 127) / 255) as u8
        };
        Rgb(
            mix(self.0, under.0),
            mix(self.1, under.1),
            mix(self.2, under.2),
        )
    }

    /// A tiny-skia paint of this colour with opacity `alpha`, anti-aliased.
    pub fn paint(self, alpha: u8) -> Paint<'static> {
        let mut paint = Paint::default();
        paint.set_color_rgba8(self.0, self.1, self.2, alpha);
        paint.anti_alias = true;
        paint
    }
}

/// An axis-aligned pixel rectangle (`x`, `y` top-left, may lie partly off canvas).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Rect {
    pub x: f32,
    pub y: f32,
    pub w: f32,
    pub h: f32,
}

impl Rect {
    pub fn new(x: f32, y: f32, w: f32, h: f32) -> Self {
        Self { x, y, w, h }
    }

    /// Area shared with `other` (0 if disjoint).
    pub fn overlap(&self, other: &Rect) -> f32 {
        let w = (self.x + self.w).min(other.x + other.w) - self.x.max(other.x);
        let h = (self.y + self.h).min(other.y + other.h) - self.y.max(other.y);
        if w > 0.0 && h > 0.0 {
            w * h
        } else {
            0.0
        }
    }

    /// Whether `other` lies entirely inside.
    pub fn contains(&self, other: &Rect) -> bool {
        other.x >= self.x
            && other.y >= self.y
            && other.x + other.w <= self.x + self.w
            && other.y + other.h <= self.y + self.h
    }
}

/// The opaque drawing surface.
pub(crate) struct Canvas {
    pub pixmap: Pixmap,
}

impl Canvas {
    /// A white canvas of `width × height` pixels.
    pub fn new(width: u32, height: u32) -> Result<Self, RenderError> {
        let mut pixmap = Pixmap::new(width.max(1), height.max(1))
            .ok_or(RenderError::TooLarge { width, height })?;
        pixmap.fill(tiny_skia::Color::WHITE);
        Ok(Self { pixmap })
    }

    /// Canvas width in pixels.
    pub fn width(&self) -> i64 {
        i64::from(self.pixmap.width())
    }

    /// Canvas height in pixels.
    pub fn height(&self) -> i64 {
        i64::from(self.pixmap.height())
    }

    /// Clips `[x, x+w) × [y, y+h)` to the canvas; `None` if nothing is left.
    fn clip(&self, x: i64, y: i64, w: i64, h: i64) -> Option<(usize, usize, usize, usize)> {
        let (x0, y0) = (x.max(0), y.max(0));
        let (x1, y1) = ((x + w).min(self.width()), (y + h).min(self.height()));
        (x1 > x0 && y1 > y0).then_some((x0 as usize, y0 as usize, x1 as usize, y1 as usize))
    }

    /// Fills a pixel rectangle with an opaque colour (clipped).
    pub fn fill_rect(&mut self, x: i64, y: i64, w: i64, h: i64, c: Rgb) {
        self.blend_rect(x, y, w, h, c, 255);
    }

    /// Blends a colour of opacity `alpha` over a pixel rectangle (clipped).
    pub fn blend_rect(&mut self, x: i64, y: i64, w: i64, h: i64, c: Rgb, alpha: u8) {
        let Some((x0, y0, x1, y1)) = self.clip(x, y, w, h) else {
            return;
        };
        let stride = self.pixmap.width() as usize * 4;
        let data = self.pixmap.data_mut();
        let a = u32::from(alpha);
        let mix = |dst: u8, src: u8| {
            ((u32::from(src) * a + u32::from(dst) * (255 - a) + 127) / 255) as u8
        };
        for row in y0..y1 {
            let line = &mut data[row * stride + x0 * 4..row * stride + x1 * 4];
            for px in line.chunks_exact_mut(4) {
                if alpha == 255 {
                    px.copy_from_slice(&[c.0, c.1, c.2, 255]);
                } else {
                    px[0] = mix(px[0], c.0);
                    px[1] = mix(px[1], c.1);
                    px[2] = mix(px[2], c.2);
                }
            }
        }
    }

    /// A 1-pixel rectangle outline (clipped).
    pub fn outline_rect(&mut self, x: i64, y: i64, w: i64, h: i64, c: Rgb) {
        self.fill_rect(x, y, w, 1, c);
        self.fill_rect(x, y + h - 1, w, 1, c);
        self.fill_rect(x, y, 1, h, c);
        self.fill_rect(x + w - 1, y, 1, h, c);
    }

    /// Copies one prepared RGBA row into canvas row `y` from column `x` (clipped).
    pub fn put_row(&mut self, x: usize, y: usize, rgba: &[u8]) {
        let (w, h) = (self.pixmap.width() as usize, self.pixmap.height() as usize);
        if y >= h || x >= w {
            return;
        }
        let n = (rgba.len() / 4).min(w - x);
        let start = (y * w + x) * 4;
        self.pixmap.data_mut()[start..start + n * 4].copy_from_slice(&rgba[..n * 4]);
    }

    /// Fills a path (anti-aliased).
    pub fn fill_path(&mut self, path: &Path, c: Rgb, alpha: u8) {
        self.pixmap.fill_path(
            path,
            &c.paint(alpha),
            FillRule::Winding,
            Transform::identity(),
            None,
        );
    }

    /// Strokes a path with round joins and caps (anti-aliased).
    pub fn stroke_path(&mut self, path: &Path, c: Rgb, alpha: u8, width: f32) {
        let stroke = Stroke {
            width,
            line_cap: LineCap::Round,
            line_join: LineJoin::Round,
            ..Stroke::default()
        };
        let mut paint = c.paint(alpha);
        paint.anti_alias = alpha == 255;
        self.pixmap
            .stroke_path(path, &paint, &stroke, Transform::identity(), None);
    }

    /// Strokes a path with dashes `dash` pixels long and as far apart, butt caps.
    pub fn stroke_dashed(&mut self, path: &Path, c: Rgb, alpha: u8, width: f32, dash: f32) {
        let stroke = Stroke {
            width,
            line_cap: LineCap::Butt,
            line_join: LineJoin::Round,
            dash: StrokeDash::new(vec![dash, dash], 0.0),
            ..Stroke::default()
        };
        self.pixmap
            .stroke_path(path, &c.paint(alpha), &stroke, Transform::identity(), None);
    }

    /// Strokes a path with the dash pattern `intervals` (on, off, on, off, … pixels;
    /// an even number of them), butt caps; solid when the pattern is unusable.
    pub fn stroke_pattern(
        &mut self,
        path: &Path,
        c: Rgb,
        alpha: u8,
        width: f32,
        intervals: &[f32],
    ) {
        let stroke = Stroke {
            width,
            line_cap: LineCap::Butt,
            line_join: LineJoin::Round,
            dash: StrokeDash::new(intervals.to_vec(), 0.0),
            ..Stroke::default()
        };
        self.pixmap
            .stroke_path(path, &c.paint(alpha), &stroke, Transform::identity(), None);
    }

    /// Fills a circle (anti-aliased).
    pub fn fill_circle(&mut self, cx: f32, cy: f32, r: f32, c: Rgb, alpha: u8) {
        if let Some(path) = PathBuilder::from_circle(cx, cy, r) {
            self.fill_path(&path, c, alpha);
        }
    }

    /// Draws `text` with its top-left corner at (`x`, `y`), glyphs scaled `scale`×,
    /// proportionally spaced.
    pub fn text(&mut self, x: i64, y: i64, text: &str, scale: u32, c: Rgb) {
        let s = i64::from(scale);
        let mut gx = x;
        for ch in text.chars() {
            let bitmap = glyph(ch);
            let (first, advance) = metrics(&bitmap);
            for (row, &bits) in bitmap.iter().enumerate() {
                let bits = bits >> first;
                let mut col = 0;
                while col < 8 {
                    if bits & (1 << col) == 0 {
                        col += 1;
                        continue;
                    }
                    // Merge runs of set bits into one rectangle.
                    let start = col;
                    while col < 8 && bits & (1 << col) != 0 {
                        col += 1;
                    }
                    self.fill_rect(gx + start * s, y + row as i64 * s, (col - start) * s, s, c);
                }
            }
            gx += advance * s;
        }
    }

    /// Encodes the canvas as an RGB PNG. The canvas is opaque, so its premultiplied
    /// pixels are the plain colours. Fast deflate with adaptive filters: about ten
    /// times faster than the default level for files about twice as large.
    pub fn encode(&self) -> Result<Vec<u8>, RenderError> {
        use image::codecs::png::{CompressionType, FilterType, PngEncoder};
        use image::ImageEncoder;
        let rgb: Vec<u8> = self
            .pixmap
            .data()
            .chunks_exact(4)
            .flat_map(|p| [p[0], p[1], p[2]])
            .collect();
        let mut png = Vec::with_capacity(rgb.len() / 8);
        PngEncoder::new_with_quality(&mut png, CompressionType::Fast, FilterType::Adaptive)
            .write_image(
                &rgb,
                self.pixmap.width(),
                self.pixmap.height(),
                image::ExtendedColorType::Rgb8,
            )
            .map_err(|e| RenderError::Encode(e.to_string()))?;
        Ok(png)
    }
}

/// Width in pixels of `text` at glyph scale `scale` (the one-column gap after the
/// last glyph included).
pub(crate) fn text_width(text: &str, scale: u32) -> i64 {
    text.chars().map(|c| metrics(&glyph(c)).1).sum::<i64>() * i64::from(scale)
}

/// The first inked column of a glyph and its advance in font pixels: the inked width
/// and a one-column gap; blank glyphs (space) advance four columns.
fn metrics(bitmap: &[u8; 8]) -> (u32, i64) {
    let ink = bitmap.iter().fold(0u8, |a, &b| a | b);
    if ink == 0 {
        return (0, 4);
    }
    let first = ink.trailing_zeros();
    let last = 7 - ink.leading_zeros();
    (first, i64::from(last - first) + 2)
}

/// Height in pixels of the ink of a line of text at `scale` (the font's 8th row is
/// the descender row, mostly empty).
pub(crate) fn text_height(scale: u32) -> i64 {
    8 * i64::from(scale)
}

/// Shortens `text` with "..." so that it fits in `max_width` pixels at `scale`.
pub(crate) fn fit_text(text: &str, scale: u32, max_width: i64) -> String {
    if text_width(text, scale) <= max_width {
        return text.to_owned();
    }
    let budget = max_width - text_width("...", scale);
    let mut used = 0;
    let mut s: String = text
        .chars()
        .take_while(|&c| {
            used += text_width(c.encode_utf8(&mut [0; 4]), scale);
            used <= budget
        })
        .collect();
    s.push_str("...");
    s
}

/// The 8×8 bitmap of a character: rows top to bottom, bit 0 the leftmost pixel.
/// Basic Latin, Latin-1 and Greek come from font8x8; a few common typographic characters
/// fall back to ASCII look-alikes, anything else shows as '?'.
fn glyph(c: char) -> [u8; 8] {
    use font8x8::legacy::{BASIC_LEGACY, GREEK_LEGACY, LATIN_LEGACY};
    let u = c as u32;
    match u {
        0x20..=0x7e => BASIC_LEGACY[u as usize],
        0xa0..=0xff => LATIN_LEGACY[(u - 0xa0) as usize],
        // The font's lowercase theta is an x-height "e" look-alike: the capital
        // reads as the angle the captions mean.
        0x3b8 => GREEK_LEGACY[0x398 - 0x390],
        0x390..=0x3c9 => GREEK_LEGACY[(u - 0x390) as usize],
        _ => {
            let fallback = match c {
                '\u{2010}'..='\u{2015}' | '\u{2212}' => '-',
                '\u{2192}' => '>',
                '\u{2018}' | '\u{2019}' => '\'',
                '\u{201c}' | '\u{201d}' => '"',
                '\u{2022}' | '\u{22c5}' => return LATIN_LEGACY[0x17],
                _ => '?',
            };
            BASIC_LEGACY[fallback as usize]
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn glyphs_cover_the_summary_characters() {
        for c in "0123456789%.·×:abcXYZθα°".chars() {
            assert_ne!(glyph(c), [0; 8], "{c:?}");
        }
        assert_eq!(glyph('\u{4e00}'), glyph('?'));
    }

    #[test]
    fn fit_text_truncates() {
        assert_eq!(fit_text("abc", 1, 100), "abc");
        let s = fit_text("abcdefghijklmnop", 1, 80);
        assert!(text_width(&s, 1) <= 80);
        assert!(s.ends_with("..."));
    }

    #[test]
    fn rect_overlap() {
        let a = Rect::new(0.0, 0.0, 10.0, 10.0);
        assert_eq!(a.overlap(&Rect::new(5.0, 5.0, 10.0, 10.0)), 25.0);
        assert_eq!(a.overlap(&Rect::new(10.0, 0.0, 5.0, 5.0)), 0.0);
        assert!(a.contains(&Rect::new(1.0, 1.0, 2.0, 2.0)));
    }
}
