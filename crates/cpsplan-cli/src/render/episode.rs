//! The episode overlay: the parent's trajectory with direction arrows, the scan
//! markers and their numbers, placed so that they do not hide one another.

use cpsplan::{Episode, Point};
use tiny_skia::PathBuilder;

use super::canvas::{text_width, Canvas, Rect, Rgb};
use super::chrome::{draw_arrowhead, draw_marker, Style};
use super::{palette, MapLayout};

/// The driven legs in canvas pixels: all points, and where each leg starts.
struct Legs {
    points: Vec<(f32, f32)>,
    starts: Vec<usize>,
}

impl Legs {
    /// Leg `i`'s points.
    fn leg(&self, i: usize) -> &[(f32, f32)] {
        let end = self.starts.get(i + 1).copied().unwrap_or(self.points.len());
        &self.points[self.starts[i]..end]
    }

    fn len(&self) -> usize {
        self.starts.len()
    }
}

/// The children's driven paths, thin, one colour per child, under the parent's.
fn draw_children(canvas: &mut Canvas, layout: &MapLayout, episode: &Episode) {
    let colours = super::palette::CHILDREN;
    for (n, colour) in (0..episode.config.children.count).zip(colours.iter().cycle()) {
        let mut pb = PathBuilder::new();
        let mut any = false;
        for cycle in episode.steps.iter().flat_map(|s| &s.movement.cycles) {
            let Some(child) = cycle.children.get(n) else {
                continue;
            };
            let pts: Vec<(f32, f32)> = child
                .path
                .iter()
                .map(|&p| layout.world_to_px(p))
                .filter(|p| p.0.is_finite() && p.1.is_finite())
                .collect();
            if let Some((first, rest)) = pts.split_first() {
                pb.move_to(first.0, first.1);
                for p in rest {
                    pb.line_to(p.0, p.1);
                }
                any |= !rest.is_empty();
            }
        }
        if let (true, Some(path)) = (any, pb.finish()) {
            canvas.stroke_path(&path, *colour, 220, 1.5);
        }
    }
}

/// The path the parent drove after a step: its CPS cycles' paths when it moved by
/// cycles, else the plan's path.
fn driven_path(step: &cpsplan::mission::Step) -> Vec<Point> {
    if step.movement.cycles.is_empty() {
        step.plan.path.clone()
    } else {
        step.movement
            .cycles
            .iter()
            .flat_map(|c| c.parent_path.iter().copied())
            .collect()
    }
}

/// Every step but the last moved the parent along its driven path to the next scan
/// position; a step without a usable path is drawn as a straight move.
fn legs(layout: &MapLayout, episode: &Episode) -> Legs {
    let steps = &episode.steps;
    let n_points: usize = steps.iter().map(|s| s.plan.path.len().max(2)).sum();
    let mut legs = Legs {
        points: Vec::with_capacity(n_points),
        starts: Vec::with_capacity(steps.len()),
    };
    let finite = |p: &(f32, f32)| p.0.is_finite() && p.1.is_finite();
    for pair in steps.windows(2) {
        let start = legs.points.len();
        legs.points.extend(
            driven_path(&pair[0])
                .iter()
                .map(|&p| layout.world_to_px(p))
                .filter(finite),
        );
        if legs.points.len() - start < 2 {
            legs.points.truncate(start);
            for p in [pair[0].position, pair[1].position] {
                legs.points.push(layout.world_to_px(p));
            }
            if !legs.points[start..].iter().all(finite) {
                legs.points.truncate(start);
                continue;
            }
        }
        legs.starts.push(start);
    }
    legs
}

/// Draws trajectory, markers and labels over the painted map.
pub(crate) fn draw_overlay(
    canvas: &mut Canvas,
    layout: &MapLayout,
    style: Style,
    episode: &Episode,
) {
    let legs = legs(layout, episode);
    draw_children(canvas, layout, episode);
    draw_trajectory(canvas, style, &legs);

    let positions: Vec<Point> = if episode.steps.is_empty() {
        vec![episode.start]
    } else {
        episode.steps.iter().map(|s| s.position).collect()
    };
    let dots: Vec<(f32, f32)> = positions.iter().map(|&p| layout.world_to_px(p)).collect();
    let last = dots.len() - 1;
    let r = style.marker_radius();
    let big = r + 1.5;
    let color_of = |i: usize| {
        if i == 0 {
            palette::START
        } else if i == last {
            palette::END
        } else {
            palette::SCAN
        }
    };
    let radius_of = |i: usize| if i == 0 || i == last { big } else { r };
    for (i, &(x, y)) in dots.iter().enumerate().skip(1) {
        if i != last {
            draw_marker(canvas, x, y, r, palette::SCAN);
        }
    }
    if last > 0 {
        draw_marker(canvas, dots[last].0, dots[last].1, big, palette::END);
    }
    draw_marker(canvas, dots[0].0, dots[0].1, big, palette::START);

    // Numbers, placed one by one where they hide the least.
    let mut placer = Placer::new(canvas, layout, &legs, &dots, big + 2.5);
    let g = i64::from(style.g);
    let pad = g + 1 + g / 2;
    let mut label = String::new();
    for (i, &dot) in dots.iter().enumerate() {
        use std::fmt::Write as _;
        if !(dot.0.is_finite() && dot.1.is_finite()) {
            continue;
        }
        label.clear();
        let _ = write!(label, "{}", i + 1);
        let w = text_width(&label, style.g) - g + 2 * pad;
        let h = 7 * g + 2 * pad;
        let required = i == 0 || i == last;
        let Some((rect, far)) = placer.place(
            i,
            dot,
            radius_of(i) + 2.5,
            w as f32,
            h as f32,
            style,
            required,
        ) else {
            continue; // no room: the marker stays, unlabelled
        };
        let (x, y) = (rect.x.round() as i64, rect.y.round() as i64);
        if far {
            let (bx, by) = (x as f32 + w as f32 / 2.0, y as f32 + h as f32 / 2.0);
            let (dx, dy) = (bx - dot.0, by - dot.1);
            let d = dx.hypot(dy).max(1.0);
            let r0 = radius_of(i) + 1.75;
            let mut pb = PathBuilder::new();
            pb.move_to(dot.0 + dx / d * r0, dot.1 + dy / d * r0);
            pb.line_to(bx, by);
            if let Some(path) = pb.finish() {
                canvas.stroke_path(&path, palette::MUTED_TEXT, 255, 1.0);
            }
        }
        let edge = if i == 0 || i == last {
            color_of(i)
        } else {
            palette::SWATCH_EDGE
        };
        canvas.blend_rect(x, y, w, h, Rgb::hex(0xffffff), 235);
        canvas.outline_rect(x, y, w, h, edge);
        canvas.text(x + pad, y + pad, &label, style.g, palette::TEXT);
    }
}

/// The trajectory: a white casing, the coloured line, and an arrowhead halfway
/// along every leg long enough to carry one.
fn draw_trajectory(canvas: &mut Canvas, style: Style, legs: &Legs) {
    let mut pb = PathBuilder::new();
    for i in 0..legs.len() {
        let leg = legs.leg(i);
        pb.move_to(leg[0].0, leg[0].1);
        for p in &leg[1..] {
            pb.line_to(p.0, p.1);
        }
    }
    let Some(path) = pb.finish() else {
        return;
    };
    let lw = style.line_width();
    canvas.stroke_path(&path, Rgb::hex(0xffffff), 215, lw + 3.5);
    canvas.stroke_path(&path, palette::TRAJECTORY, 255, lw);
    for i in 0..legs.len() {
        let leg = legs.leg(i);
        let seg_len = |w: &[(f32, f32)]| (w[1].0 - w[0].0).hypot(w[1].1 - w[0].1);
        let total: f32 = leg.windows(2).map(seg_len).sum();
        if total < 16.0 * lw {
            continue;
        }
        let mut rest = total / 2.0;
        for w in leg.windows(2) {
            let l = seg_len(w);
            if l <= 0.0 {
                continue;
            }
            if rest <= l {
                let (dx, dy) = ((w[1].0 - w[0].0) / l, (w[1].1 - w[0].1) / l);
                let at = (w[0].0 + dx * rest, w[0].1 + dy * rest);
                draw_arrowhead(canvas, style, at, (dx, dy), palette::TRAJECTORY);
                break;
            }
            rest -= l;
        }
    }
}

/// Greedy label placement: each label goes to the candidate spot around its marker
/// that overlaps markers, earlier labels and the trajectory the least.
struct Placer {
    /// Marker squares, then placed labels.
    taken: Vec<Rect>,
    /// `taken` by the tiles each rectangle touches.
    index: TileIndex,
    /// Number of markers at the start of `taken`.
    markers: usize,
    /// The map's pixel rectangle: labels should stay inside.
    map: Rect,
    /// The canvas: labels must stay inside.
    canvas: Rect,
    /// Where the trajectory runs.
    mask: TrajectoryMask,
}

impl Placer {
    fn new(
        canvas: &Canvas,
        layout: &MapLayout,
        legs: &Legs,
        dots: &[(f32, f32)],
        marker_radius: f32,
    ) -> Self {
        let h = marker_radius * 0.85;
        let mut taken = Vec::with_capacity(2 * dots.len());
        taken.extend(
            dots.iter()
                .map(|&(x, y)| Rect::new(x - h, y - h, 2.0 * h, 2.0 * h)),
        );
        let mut index = TileIndex::new(canvas.width(), canvas.height(), taken.len());
        for (i, r) in taken.iter().enumerate() {
            index.insert(i, r);
        }
        let mut mask = TrajectoryMask::new(canvas.width(), canvas.height());
        for i in 0..legs.len() {
            for w in legs.leg(i).windows(2) {
                mask.mark_segment(w[0], w[1]);
            }
        }
        Self {
            markers: taken.len(),
            taken,
            index,
            map: layout.rect(),
            canvas: Rect::new(0.0, 0.0, canvas.width() as f32, canvas.height() as f32),
            mask,
        }
    }

    /// Chooses the box of `w × h` pixels for marker `index` at `dot` of radius `r`;
    /// also says whether it sits away from the marker (and needs a leader line).
    /// Where every spot would cover more than a sixth of an earlier label, the label
    /// is left out (`None`) unless it is `required`: in dense clusters of scans an
    /// unreadable pile of numbers helps nobody.
    #[allow(clippy::too_many_arguments)]
    fn place(
        &mut self,
        index: usize,
        dot: (f32, f32),
        r: f32,
        w: f32,
        h: f32,
        style: Style,
        required: bool,
    ) -> Option<(Rect, bool)> {
        const DIRS: [(f32, f32); 8] = [
            (1.0, -1.0),
            (-1.0, -1.0),
            (1.0, 1.0),
            (-1.0, 1.0),
            (1.0, 0.0),
            (-1.0, 0.0),
            (0.0, -1.0),
            (0.0, 1.0),
        ];
        let (cx, cy) = dot;
        let mut best = (f32::INFINITY, Rect::new(cx, cy, w, h), false);
        for ring in 0..2 {
            let d = r + 1.5 + ring as f32 * 12.0 * style.g as f32;
            for (k, &(ux, uy)) in DIRS.iter().enumerate() {
                let diag = if ux != 0.0 && uy != 0.0 { 0.72 } else { 1.0 };
                let x = match ux {
                    u if u > 0.0 => cx + d * diag,
                    u if u < 0.0 => cx - d * diag - w,
                    _ => cx - w / 2.0,
                };
                let y = match uy {
                    u if u > 0.0 => cy + d * diag,
                    u if u < 0.0 => cy - d * diag - h,
                    _ => cy - h / 2.0,
                };
                let rect = Rect::new(x.round(), y.round(), w, h);
                let cost = self.cost(index, &rect) + k as f32 * 3.0 + ring as f32 * 900.0;
                if cost < best.0 {
                    best = (cost, rect, ring > 0);
                }
            }
            if best.0 < 100.0 {
                break;
            }
        }
        if !required && self.label_overlap(&best.1) > w * h / 6.0 {
            return None;
        }
        self.index.insert(self.taken.len(), &best.1);
        self.taken.push(best.1);
        Some((best.1, best.2))
    }

    /// Area of `rect` covered by labels placed so far.
    fn label_overlap(&mut self, rect: &Rect) -> f32 {
        let (taken, markers) = (&self.taken, self.markers);
        let mut area = 0.0;
        self.index.for_each_near(rect, |j| {
            if j >= markers {
                area += rect.overlap(&taken[j]);
            }
        });
        area
    }

    /// How much a label at `rect` would hide: leaving the canvas or the map, covering
    /// markers (other than its own, `index`) or earlier labels, crossing the trajectory.
    fn cost(&mut self, index: usize, rect: &Rect) -> f32 {
        let mut cost = 0.0;
        if !self.canvas.contains(rect) {
            cost += 1e7;
        } else if !self.map.contains(rect) {
            cost += 3000.0;
        }
        let (taken, markers) = (&self.taken, self.markers);
        self.index.for_each_near(rect, |j| {
            if j != index {
                let weight = if j < markers { 60.0 } else { 40.0 };
                cost += weight * rect.overlap(&taken[j]);
            }
        });
        cost + 40.0 * self.mask.covered(rect) as f32
    }
}

/// Rectangles by the 64 × 64 pixel tiles of the canvas they touch, so that a
/// placement looks only at its neighbours.
struct TileIndex {
    cols: usize,
    rows: usize,
    tiles: Vec<Vec<usize>>,
    /// Per rectangle, the last query that visited it (to visit each once).
    seen: Vec<u32>,
    query: u32,
}

const TILE: f32 = 64.0;

impl TileIndex {
    fn new(width: i64, height: i64, capacity: usize) -> Self {
        let cols = (width.max(1) as usize).div_ceil(TILE as usize);
        let rows = (height.max(1) as usize).div_ceil(TILE as usize);
        Self {
            cols,
            rows,
            tiles: vec![Vec::new(); cols * rows],
            seen: Vec::with_capacity(capacity),
            query: 0,
        }
    }

    /// The tile ranges `rect` touches (clamped to the canvas).
    fn span(&self, rect: &Rect) -> (usize, usize, usize, usize) {
        let tile = |v: f32, n: usize| ((v / TILE).max(0.0) as usize).min(n - 1);
        (
            tile(rect.x, self.cols),
            tile(rect.y, self.rows),
            tile(rect.x + rect.w, self.cols),
            tile(rect.y + rect.h, self.rows),
        )
    }

    fn insert(&mut self, id: usize, rect: &Rect) {
        let (c0, r0, c1, r1) = self.span(rect);
        for r in r0..=r1 {
            for c in c0..=c1 {
                self.tiles[r * self.cols + c].push(id);
            }
        }
        if self.seen.len() <= id {
            self.seen.resize(id + 1, 0);
        }
    }

    /// Calls `f` once for every rectangle sharing a tile with `rect`.
    fn for_each_near(&mut self, rect: &Rect, mut f: impl FnMut(usize)) {
        self.query = self.query.wrapping_add(1);
        if self.query == 0 {
            self.seen.fill(0);
            self.query = 1;
        }
        let (c0, r0, c1, r1) = self.span(rect);
        for r in r0..=r1 {
            for c in c0..=c1 {
                for &id in &self.tiles[r * self.cols + c] {
                    if self.seen[id] != self.query {
                        self.seen[id] = self.query;
                        f(id);
                    }
                }
            }
        }
    }
}

/// Which 4 × 4 pixel blocks of the canvas the trajectory crosses.
struct TrajectoryMask {
    cols: usize,
    rows: usize,
    bits: Vec<bool>,
}

const BLOCK: f32 = 4.0;

impl TrajectoryMask {
    fn new(width: i64, height: i64) -> Self {
        let cols = (width.max(1) as usize).div_ceil(BLOCK as usize);
        let rows = (height.max(1) as usize).div_ceil(BLOCK as usize);
        Self {
            cols,
            rows,
            bits: vec![false; cols * rows],
        }
    }

    fn mark_segment(&mut self, a: (f32, f32), b: (f32, f32)) {
        let len = (b.0 - a.0).hypot(b.1 - a.1);
        let n = ((len / 2.0).ceil() as usize).clamp(1, 100_000);
        for k in 0..=n {
            let t = k as f32 / n as f32;
            let (x, y) = (a.0 + (b.0 - a.0) * t, a.1 + (b.1 - a.1) * t);
            if x >= 0.0 && y >= 0.0 {
                let (c, r) = ((x / BLOCK) as usize, (y / BLOCK) as usize);
                if c < self.cols && r < self.rows {
                    self.bits[r * self.cols + c] = true;
                }
            }
        }
    }

    fn covered(&self, rect: &Rect) -> usize {
        let c0 = (rect.x / BLOCK).max(0.0) as usize;
        let r0 = (rect.y / BLOCK).max(0.0) as usize;
        let c1 = (((rect.x + rect.w) / BLOCK).max(0.0).ceil() as usize).min(self.cols);
        let r1 = (((rect.y + rect.h) / BLOCK).max(0.0).ceil() as usize).min(self.rows);
        (r0..r1)
            .map(|r| {
                self.bits[r * self.cols + c0.min(c1)..r * self.cols + c1]
                    .iter()
                    .filter(|&&b| b)
                    .count()
            })
            .sum()
    }
}
