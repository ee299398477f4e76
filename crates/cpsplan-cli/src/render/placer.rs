//! Greedy placement of marker labels (scan numbers, candidate scores) so that they
//! hide as little as possible of the markers, the other labels and the paths.

use tiny_skia::PathBuilder;

use super::canvas::{text_width, Canvas, Rect, Rgb};
use super::chrome::Style;
use super::layout::MapLayout;
use super::palette;

/// Greedy label placement: each label goes to the candidate spot around its marker
/// that overlaps markers, earlier labels and the trajectory the least.
pub(crate) struct Placer {
    /// Marker squares, then placed labels.
    taken: Vec<Rect>,
    /// `taken` by the tiles each rectangle touches.
    index: TileIndex,
    /// Number of markers at the start of `taken`.
    markers: usize,
    /// The first this many markers may not be covered by labels (but their own).
    protected: usize,
    /// The map's pixel rectangle: labels should stay inside.
    map: Rect,
    /// The canvas: labels must stay inside.
    canvas: Rect,
    /// Where the paths run.
    mask: TrajectoryMask,
    /// The markers of the label being placed (besides its `index`).
    own: std::ops::Range<usize>,
}

impl Placer {
    /// A placer for labels of the markers at `dots` (drawn with radius
    /// `marker_radius`) over a map crossed by the polylines `paths`.
    pub fn new<'p>(
        canvas: &Canvas,
        layout: &MapLayout,
        paths: impl IntoIterator<Item = &'p [(f32, f32)]>,
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
        for path in paths {
            for w in path.windows(2) {
                mask.mark_segment(w[0], w[1]);
            }
        }
        Self {
            protected: 0,
            markers: taken.len(),
            taken,
            index,
            map: layout.rect(),
            canvas: Rect::new(0.0, 0.0, canvas.width() as f32, canvas.height() as f32),
            mask,
            own: 0..0,
        }
    }

    /// Keeps labels off the first `count` markers (other than their own) as they keep
    /// off other labels.
    pub fn protect_markers(&mut self, count: usize) {
        self.protected = count.min(self.markers);
    }

    /// [`Self::place`] for a label of the markers `own` (a run of scans).
    #[allow(clippy::too_many_arguments)]
    pub fn place_for(
        &mut self,
        own: std::ops::Range<usize>,
        dot: (f32, f32),
        r: f32,
        w: f32,
        h: f32,
        style: Style,
        required: bool,
    ) -> Option<(Rect, bool)> {
        self.own = own;
        let placed = self.place(self.own.start, dot, r, w, h, style, required);
        self.own = 0..0;
        placed
    }

    /// Chooses the box of `w × h` pixels for marker `index` at `dot` of radius `r`;
    /// also says whether it sits away from the marker (and needs a leader line).
    /// Labels never overlap one another (nor protected markers): where every spot
    /// near the marker would cover an earlier label the label is left out (`None`) unless it is
    /// `required`, which then looks further out (and only when the whole
    /// neighbourhood is taken overlaps the least).
    #[allow(clippy::too_many_arguments)]
    pub fn place(
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
        let rings = if required { 6 } else { 2 };
        let mut best: Option<(f32, Rect, bool)> = None;
        let mut fallback = (f32::INFINITY, Rect::new(cx, cy, w, h), false);
        for ring in 0..rings {
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
                if cost < fallback.0 {
                    fallback = (cost, rect, ring > 0);
                }
                let free = self.canvas.contains(&rect) && self.label_overlap(index, &rect) == 0.0;
                if free && best.is_none_or(|b| cost < b.0) {
                    best = Some((cost, rect, ring > 0));
                }
            }
            match best {
                Some(b) if b.0 < 100.0 || ring >= 1 => break,
                _ => {}
            }
        }
        let (_, rect, far) = match best {
            Some(b) => b,
            None if required => fallback,
            None => return None,
        };
        self.reserve(rect);
        Some((rect, far))
    }

    /// Keeps later labels off `rect` (a placed label, or another box of text).
    pub fn reserve(&mut self, rect: Rect) {
        self.index.insert(self.taken.len(), &rect);
        self.taken.push(rect);
    }

    /// Area of `rect` covered by labels placed so far and by protected markers
    /// other than those of the label (`index` and `own`).
    fn label_overlap(&mut self, index: usize, rect: &Rect) -> f32 {
        let (taken, markers, protected) = (&self.taken, self.markers, self.protected);
        let own = self.own.clone();
        let mut area = 0.0;
        self.index.for_each_near(rect, |j| {
            let counts = j >= markers || (j < protected && j != index && !own.contains(&j));
            if counts {
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
        let own = self.own.clone();
        self.index.for_each_near(rect, |j| {
            if j != index && !own.contains(&j) {
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

/// Size in pixels (width, height) of the box of a label showing `text`.
pub(crate) fn label_size(text: &str, style: Style) -> (i64, i64) {
    let g = i64::from(style.g);
    let pad = label_pad(style);
    (text_width(text, style.g) - g + 2 * pad, 7 * g + 2 * pad)
}

fn label_pad(style: Style) -> i64 {
    let g = i64::from(style.g);
    g + 1 + g / 2
}

/// Draws a label box placed by [`Placer::place`] at `rect`, outlined in `edge`. When
/// the box sits away from its marker (`leader`: the marker's centre and radius), a
/// thin leader line joins them.
pub(crate) fn draw_label(
    canvas: &mut Canvas,
    style: Style,
    rect: &Rect,
    text: &str,
    edge: Rgb,
    leader: Option<((f32, f32), f32)>,
) {
    let (x, y) = (rect.x.round() as i64, rect.y.round() as i64);
    let (w, h) = (rect.w.round() as i64, rect.h.round() as i64);
    if let Some((dot, r0)) = leader {
        let (bx, by) = (x as f32 + w as f32 / 2.0, y as f32 + h as f32 / 2.0);
        let (dx, dy) = (bx - dot.0, by - dot.1);
        let d = dx.hypot(dy).max(1.0);
        let mut pb = PathBuilder::new();
        pb.move_to(dot.0 + dx / d * r0, dot.1 + dy / d * r0);
        pb.line_to(bx, by);
        if let Some(path) = pb.finish() {
            canvas.stroke_path(&path, palette::MUTED_TEXT, 255, 1.0);
        }
    }
    let pad = label_pad(style);
    canvas.blend_rect(x, y, w, h, Rgb::hex(0xffffff), 235);
    canvas.outline_rect(x, y, w, h, edge);
    canvas.text(x + pad, y + pad, text, style.g, palette::TEXT);
}
