//! The AND regions of a step's CPS cycles, tinted over the painted map.

use super::super::canvas::{Canvas, Rgb};
use super::super::layout::MapLayout;
use super::super::palette;

/// Opacity of the AND-region tint of cycle 1, 2, 3 and later cycles.
const TINT_ALPHA: [u8; 4] = [110, 72, 50, 38];
/// Opacity of the outline of the AND region of cycle 1 and of later cycles.
const TINT_EDGE_ALPHA: [u8; 2] = [230, 150];

/// The tint of the AND region of cycle `level` (from 1) over free space.
pub(in crate::render) fn and_region_colour(level: usize) -> Rgb {
    let alpha = TINT_ALPHA[level.clamp(1, TINT_ALPHA.len()) - 1];
    palette::AND_REGION.over(palette::FREE, alpha)
}

/// Tints the AND regions over the painted map: every pixel of a cell of level `l`
/// blended with the tint of cycle `l`, with a thin darker outline where the region
/// ends.
pub(super) fn tint(
    canvas: &mut Canvas,
    layout: &MapLayout,
    width: usize,
    height: usize,
    levels: &[u8],
) {
    if levels.iter().all(|&l| l == 0) {
        return;
    }
    let (k, s) = (layout.cells_per_px, layout.px_per_cell);
    let cell_of = |px: usize| if k == 1 { px / s } else { px * k };
    let (wp, hp) = (layout.width_px as usize, layout.height_px as usize);
    let cols: Vec<usize> = (0..wp).map(|px| cell_of(px).min(width - 1)).collect();
    let rows: Vec<usize> = (0..hp)
        .map(|py| height - 1 - cell_of(py).min(height - 1))
        .collect();
    let level_at = |px: usize, py: usize| levels[rows[py] * width + cols[px]];
    let stride = canvas.pixmap.width() as usize;
    let (x0, y0) = (layout.x0.max(0) as usize, layout.y0.max(0) as usize);
    let data = canvas.pixmap.data_mut();
    for py in 0..hp {
        for px in 0..wp {
            let l = level_at(px, py);
            if l == 0 {
                continue;
            }
            let outside = |nl: u8| nl == 0 || nl > l;
            let edge = (px > 0 && outside(level_at(px - 1, py)))
                || (px + 1 < wp && outside(level_at(px + 1, py)))
                || (py > 0 && outside(level_at(px, py - 1)))
                || (py + 1 < hp && outside(level_at(px, py + 1)));
            let alpha = if edge {
                TINT_EDGE_ALPHA[usize::from(l > 1)]
            } else {
                TINT_ALPHA[usize::from(l).min(TINT_ALPHA.len()) - 1]
            };
            let i = ((y0 + py) * stride + x0 + px) * 4;
            let Some(p) = data.get_mut(i..i + 3) else {
                continue;
            };
            let under = Rgb(p[0], p[1], p[2]);
            let Rgb(r, g, b) = palette::AND_REGION.over(under, alpha);
            p.copy_from_slice(&[r, g, b]);
        }
    }
}
