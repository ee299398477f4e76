//! How the children are told apart in the episode picture: each child has its own
//! colour, dash pattern for its paths and mark shape for where it stood at each
//! scan (the parent's path is solid, its scans round).

use tiny_skia::{Path, PathBuilder};

use super::canvas::{Canvas, Rgb};
use super::chrome::Style;
use super::palette;

/// The shape of a child's standing marks.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Shape {
    Square,
    TriangleUp,
    TriangleDown,
    Hexagon,
}

/// How child `n` (from 0) is drawn.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct ChildLook {
    /// Colour of its paths and marks.
    pub colour: Rgb,
    /// Dash pattern of its paths at glyph scale 1 (on, off, … pixels).
    pub dash: [f32; 4],
    /// Shape of its standing marks.
    pub shape: Shape,
}

/// The look of child `n` (from 0); looks repeat after four children.
pub(crate) fn child_look(n: usize) -> ChildLook {
    const DASHES: [[f32; 4]; 4] = [
        [9.0, 4.0, 9.0, 4.0],
        [2.5, 3.0, 2.5, 3.0],
        [9.0, 3.0, 2.5, 3.0],
        [16.0, 4.0, 16.0, 4.0],
    ];
    const SHAPES: [Shape; 4] = [
        Shape::Square,
        Shape::TriangleUp,
        Shape::TriangleDown,
        Shape::Hexagon,
    ];
    let k = n % 4;
    ChildLook {
        colour: palette::CHILDREN[k],
        dash: DASHES[k],
        shape: SHAPES[k],
    }
}

impl ChildLook {
    /// Width of the path stroke.
    pub fn line_width(self, style: Style) -> f32 {
        if style.g >= 2 {
            2.0
        } else {
            1.5
        }
    }

    /// Strokes `path` in the child's colour and dash pattern.
    pub fn stroke(self, canvas: &mut Canvas, style: Style, path: &Path) {
        let g = style.g as f32;
        let dash = self.dash.map(|d| d * g);
        canvas.stroke_pattern(path, self.colour, 235, self.line_width(style), &dash);
    }

    /// Half the size of a standing mark.
    pub fn mark_radius(style: Style) -> f32 {
        style.marker_radius() * 0.6
    }

    /// A standing mark centred at (`cx`, `cy`): the child's shape in its colour
    /// with a white rim.
    pub fn draw_mark(self, canvas: &mut Canvas, style: Style, cx: f32, cy: f32) {
        let r = Self::mark_radius(style);
        if let Some(path) = self.outline(cx, cy, r + 1.6) {
            canvas.fill_path(&path, Rgb::hex(0xffffff), 255);
        }
        if let Some(path) = self.outline(cx, cy, r) {
            canvas.fill_path(&path, self.colour, 255);
        }
    }

    fn outline(self, cx: f32, cy: f32, r: f32) -> Option<Path> {
        let corners: &[(f32, f32)] = match self.shape {
            Shape::Square => &[(-0.85, -0.85), (0.85, -0.85), (0.85, 0.85), (-0.85, 0.85)],
            Shape::TriangleUp => &[(0.0, -1.15), (1.05, 0.75), (-1.05, 0.75)],
            Shape::TriangleDown => &[(0.0, 1.15), (1.05, -0.75), (-1.05, -0.75)],
            Shape::Hexagon => &[
                (1.0, 0.0),
                (0.5, -0.87),
                (-0.5, -0.87),
                (-1.0, 0.0),
                (-0.5, 0.87),
                (0.5, 0.87),
            ],
        };
        let mut pb = PathBuilder::new();
        for (k, &(x, y)) in corners.iter().enumerate() {
            let (px, py) = (cx + x * r, cy + y * r);
            if k == 0 {
                pb.move_to(px, py);
            } else {
                pb.line_to(px, py);
            }
        }
        pb.close();
        pb.finish()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_first_four_children_look_different() {
        let looks: Vec<ChildLook> = (0..4).map(child_look).collect();
        for (i, a) in looks.iter().enumerate() {
            for b in &looks[i + 1..] {
                assert_ne!(a.colour, b.colour);
                assert_ne!(a.dash, b.dash);
                assert_ne!(a.shape, b.shape);
            }
            assert_ne!(a.colour, palette::TRAJECTORY);
        }
    }
}
