//! The HTML report of an episode (`explore --html`, `report.html`): one
//! self-contained page, no network, that steps through the scans with a slider
//! or a player. It shows the knowledge map as it grew, the parent's paths and
//! scan positions, the children and their paths, the AND regions of each move's
//! cycles, the candidates of each planning round by their `G`, the error
//! ellipses, plots of coverage, error and travel with the current scan marked,
//! and the summary.
//!
//! The map travels as one deflated raster of, per cell, the scan that first saw
//! it and its final state (three bytes), so any scan's map is drawn from it in
//! one pass; AND regions travel as row runs on a grid coarsened to at most
//! 96 cells a side.

pub mod episodes;

use std::io::Write as _;

use anyhow::Result;
use base64::Engine as _;
use cpsplan::mission::{move_and_regions, Episode, Step, TargetOrigin};
use cpsplan::parent::Decision;
use cpsplan::{CellState, Config, GridGeometry, OccupancyGrid, Point};
use serde::Serialize;

use crate::render::palette;
use crate::render::upright::{upright, upright_order};

/// The longer side of an AND region's grid, at most, in cells.
const AND_CELLS: usize = 96;

/// The page, with `__TITLE__` and `__DATA__` to fill.
const TEMPLATE: &str = include_str!("player.html");

/// An AND region as row runs: `runs` holds `(row, x_start, x_end)` triples in
/// cells of `scale` map cells from `(x0, y0)`.
#[derive(Debug, Clone, Serialize)]
struct Region {
    child: usize,
    x0: usize,
    y0: usize,
    scale: usize,
    runs: Vec<u32>,
}

/// What the page needs of one step beyond the episode record.
#[derive(Debug, Clone, Default)]
struct StepExtras {
    and: Vec<Region>,
}

/// Collects, while an episode runs, what its page needs from each step's
/// knowledge map: when each cell was first seen, and the AND regions.
#[derive(Debug)]
pub struct PageRecorder {
    /// The page's grid: the episode's, turned upright (world +x right, +y
    /// up: `render::upright`).
    geometry: GridGeometry,
    /// For a turned grid, the page's index of each cell of the episode's grid.
    to_page: Option<Vec<usize>>,
    /// By the page's cell index.
    first_seen: Vec<u16>,
    steps: Vec<StepExtras>,
}

impl PageRecorder {
    /// A recorder for episodes on grids of `geometry`.
    pub fn new(geometry: GridGeometry) -> Self {
        let (geometry, to_page) = match upright_order(&geometry) {
            Some((page, order)) => {
                let mut to_page = vec![0; order.len()];
                for (new, &old) in order.iter().enumerate() {
                    to_page[old] = new;
                }
                (page, Some(to_page))
            }
            None => (geometry, None),
        };
        Self {
            geometry,
            to_page,
            first_seen: vec![0; geometry.len()],
            steps: Vec::new(),
        }
    }

    /// The page's index of cell `i` of the episode's grid.
    fn page_index(&self, i: usize) -> usize {
        self.to_page.as_ref().map_or(i, |t| t[i])
    }

    /// Records `step`, planned on `knowledge`.
    pub fn record(&mut self, step: &Step, knowledge: &OccupancyGrid, config: &Config) {
        let scan = u16::try_from(step.scan).unwrap_or(u16::MAX);
        for (i, &c) in knowledge.cells().iter().enumerate() {
            let page = self.page_index(i);
            let seen = &mut self.first_seen[page];
            if *seen == 0 && c != CellState::Unknown {
                *seen = scan;
            }
        }
        let mut and = Vec::new();
        for regions in move_and_regions(knowledge, &step.movement.cycles, config) {
            for (child, region) in regions.iter().enumerate() {
                let cells: Vec<u32> = region
                    .cells
                    .iter()
                    .map(|&i| u32::try_from(self.page_index(i as usize)).unwrap_or(i))
                    .collect();
                if let Some(r) = coarse_runs(&self.geometry, &cells, child) {
                    and.push(r);
                }
            }
        }
        self.steps.push(StepExtras { and });
    }
}

/// The runs of the region of `cells` (grid indices) on a grid coarse enough
/// that its bounding box has at most [`AND_CELLS`] cells a side (a coarse cell
/// is in if any of its cells is).
fn coarse_runs(g: &GridGeometry, cells: &[u32], child: usize) -> Option<Region> {
    let w = g.width;
    let at = |i: u32| (i as usize % w, i as usize / w);
    let (mut x0, mut y0, mut x1, mut y1) = (usize::MAX, usize::MAX, 0, 0);
    for &i in cells {
        let (x, y) = at(i);
        x0 = x0.min(x);
        y0 = y0.min(y);
        x1 = x1.max(x);
        y1 = y1.max(y);
    }
    if x0 == usize::MAX {
        return None;
    }
    let span = (x1 - x0 + 1).max(y1 - y0 + 1);
    let scale = span.div_ceil(AND_CELLS).max(1);
    let (cw, ch) = ((x1 - x0) / scale + 1, (y1 - y0) / scale + 1);
    let mut coarse = vec![false; cw * ch];
    for &i in cells {
        let (x, y) = at(i);
        coarse[(y - y0) / scale * cw + (x - x0) / scale] = true;
    }
    let mut runs = Vec::new();
    for row in 0..ch {
        let cells = &coarse[row * cw..(row + 1) * cw];
        let mut x = 0;
        while x < cw {
            if cells[x] {
                let start = x;
                while x < cw && cells[x] {
                    x += 1;
                }
                runs.extend([row as u32, start as u32, x as u32]);
            } else {
                x += 1;
            }
        }
    }
    Some(Region {
        child,
        x0,
        y0,
        scale,
        runs,
    })
}

/// One step as the page reads it; points in grid cell units (x right, y up).
#[derive(Debug, Serialize)]
struct PageStep {
    pos: [f64; 2],
    world: [f64; 2],
    coverage: f64,
    wall_coverage: f64,
    travel: f64,
    sigma_mm: Option<f64>,
    /// The smoothed σ (every measurement of the episode), mm.
    smoothed_mm: Option<f64>,
    /// Semi-axes (cells, 1σ) and the major axis's angle from the grid's x axis.
    ellipse: Option<[f64; 3]>,
    /// Measurements to targets on the way to this scan and at it: (target,
    /// station).
    sights: Vec<(usize, [f64; 2])>,
    children: Vec<[f64; 2]>,
    /// The path driven after the scan.
    path: Vec<[f64; 2]>,
    child_paths: Vec<Vec<[f64; 2]>>,
    /// `(x, y, G, eligible)`.
    candidates: Vec<(f64, f64, f64, u8)>,
    target: Option<usize>,
    cycles: usize,
    subgoals: bool,
    and: Vec<Region>,
}

/// A target or control point as the page reads it.
#[derive(Debug, Serialize)]
struct PageTarget {
    pos: [f64; 2],
    name: String,
    /// `control`, `free` or `placed`.
    kind: &'static str,
    /// The first scan at which it stands (1 for given points).
    from: usize,
    /// Its smoothed σ at the end, mm.
    sigma_mm: Option<f64>,
}

#[derive(Debug, Serialize)]
struct PageGrid {
    width: usize,
    height: usize,
    resolution: f64,
}

#[derive(Debug, Serialize)]
struct PageData {
    title: String,
    subtitle: String,
    grid: PageGrid,
    cells: String,
    steps: Vec<PageStep>,
    targets: Vec<PageTarget>,
    summary: Vec<(String, String)>,
    legend: Vec<(String, String)>,
    colours: PageColours,
}

/// The colours the page shares with the report's pictures (`render::palette`).
#[derive(Debug, Serialize)]
struct PageColours {
    path: String,
    scan: String,
    ellipse: String,
    /// Child 1 first, repeated for more children.
    children: Vec<String>,
    target: String,
    control: String,
    sight: String,
    smoothed: String,
}

/// Grid cell units of a world point.
fn cell_units(g: &GridGeometry, p: Point) -> [f64; 2] {
    let (x, y) = g.to_local(p);
    [x / g.resolution, y / g.resolution]
}

/// The 1σ ellipse of a covariance (m², world frame) in cell units of `g`.
fn ellipse(g: &GridGeometry, c: [[f64; 2]; 2]) -> Option<[f64; 3]> {
    let (a, b, d) = (c[0][0], c[0][1], c[1][1]);
    if !(a.is_finite() && b.is_finite() && d.is_finite()) {
        return None;
    }
    let mean = 0.5 * (a + d);
    let spread = (0.25 * (a - d).powi(2) + b * b).sqrt();
    let (major, minor) = ((mean + spread).max(0.0), (mean - spread).max(0.0));
    // The major axis's angle in the world frame, then in the grid's.
    let angle = 0.5 * (2.0 * b).atan2(a - d) - g.yaw;
    Some([
        major.sqrt() / g.resolution,
        minor.sqrt() / g.resolution,
        angle,
    ])
}

/// The page of `episode` (with the extras `recorder` collected as it ran).
pub fn episode_page(
    episode: &Episode,
    recorder: &PageRecorder,
    title: &str,
    map_label: &str,
) -> Result<String> {
    let g = &recorder.geometry;
    // The knowledge map in the page's (upright) cell order.
    let knowledge = episode.knowledge.as_ref().map(upright);
    let mut raw = Vec::with_capacity(3 * g.len());
    for (i, &seen) in recorder.first_seen.iter().enumerate() {
        let state = match knowledge.as_ref().map(|k| k.cells()[i]) {
            Some(CellState::Free) => 1u8,
            Some(CellState::Occupied) => 2,
            _ => 0,
        };
        let [lo, hi] = seen.to_le_bytes();
        raw.extend_from_slice(&[lo, hi, state]);
    }
    let mut z = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::default());
    z.write_all(&raw)?;
    let cells = base64::engine::general_purpose::STANDARD.encode(z.finish()?);
    let pts = |ps: &[Point]| -> Vec<[f64; 2]> { ps.iter().map(|&p| cell_units(g, p)).collect() };
    let children = episode.config.children.count;
    let steps: Vec<PageStep> = episode
        .steps
        .iter()
        .enumerate()
        .map(|(k, s)| {
            let mut child_paths = vec![Vec::new(); children];
            for cycle in &s.movement.cycles {
                for (c, m) in cycle.children.iter().enumerate() {
                    if let Some(path) = child_paths.get_mut(c) {
                        path.extend(pts(&m.path));
                    }
                }
            }
            let mut sights: Vec<(usize, [f64; 2])> = Vec::new();
            match k.checked_sub(1).and_then(|p| episode.steps.get(p)) {
                None => sights.extend(s.targets.iter().map(|&t| (t, cell_units(g, s.position)))),
                Some(before) => {
                    for c in &before.movement.cycles {
                        let from = cell_units(g, c.parent_from);
                        sights.extend(c.left_targets.iter().map(|l| (l.target, from)));
                        let to = cell_units(g, c.parent_to);
                        sights.extend(c.targets.iter().map(|&t| (t, to)));
                    }
                }
            }
            PageStep {
                pos: cell_units(g, s.position),
                world: [s.position.x, s.position.y],
                coverage: s.coverage,
                wall_coverage: s.wall_coverage,
                travel: s.parent_travel_m,
                sigma_mm: s.position_sigma_m.map(|v| 1e3 * v),
                smoothed_mm: s.smoothed_sigma_m.map(|v| 1e3 * v),
                ellipse: s.covariance_m2.and_then(|c| ellipse(g, c)),
                sights,
                children: pts(&s.children),
                path: pts(&s.driven_path()),
                child_paths,
                candidates: s
                    .plan
                    .candidates
                    .iter()
                    .map(|c| {
                        let [x, y] = cell_units(g, c.position);
                        (x, y, c.g, u8::from(c.eligible))
                    })
                    .collect(),
                target: match s.plan.decision {
                    Decision::Target { index } => Some(index),
                    _ => None,
                },
                cycles: s.movement.cycles.len(),
                subgoals: s.movement.subgoal_retrieval,
                and: recorder
                    .steps
                    .get(k)
                    .map(|e| e.and.clone())
                    .unwrap_or_default(),
            }
        })
        .collect();
    let s = &episode.summary;
    let mm = |v: Option<f64>| v.map_or("—".into(), |v| format!("{:.1} mm", 1e3 * v));
    let summary = vec![
        ("map".into(), map_label.to_string()),
        ("scans".into(), s.scans.to_string()),
        ("coverage".into(), format!("{:.2} %", 100.0 * s.coverage)),
        (
            "walls seen".into(),
            format!("{:.2} %", 100.0 * s.wall_coverage),
        ),
        (
            "parent travel".into(),
            format!("{:.1} m", s.parent_travel_m),
        ),
        (
            "children's travel".into(),
            if s.child_travel_m.is_empty() {
                "—".into()
            } else {
                s.child_travel_m
                    .iter()
                    .map(|t| format!("{t:.0}"))
                    .collect::<Vec<_>>()
                    .join(", ")
                    + " m"
            },
        ),
        ("CPS cycles".into(), s.cps_cycles.to_string()),
        (
            "moves with subgoals".into(),
            s.subgoal_retrievals.to_string(),
        ),
        ("final error (1σ)".into(), mm(s.final_position_sigma_m)),
        (
            "worst error (1σ): when scanned, smoothed".into(),
            format!(
                "{}, {}",
                mm(s.worst_position_sigma_m),
                mm(s.worst_smoothed_sigma_m)
            ),
        ),
        (
            "error / travel".into(),
            s.error_percent_of_travel
                .map_or("—".into(), |p| format!("{p:.4} %")),
        ),
        (
            "campaign time".into(),
            format!("{:.1} h", s.campaign_time_h),
        ),
        ("stop".into(), s.stop_reason.name().to_string()),
        ("planner".into(), s.planner.name().to_string()),
        (
            "targets, closures".into(),
            format!("{}, {}", episode.targets.len(), s.closures),
        ),
        (
            "children, strategy".into(),
            format!("{children}, {}", episode.config.children.strategy.name()),
        ),
        ("instrument".into(), s.instrument.clone()),
        ("seed".into(), s.seed.to_string()),
    ];
    let colours = PageColours {
        path: palette::TRAJECTORY.css(),
        scan: palette::SCAN.css(),
        ellipse: palette::ELLIPSE.css(),
        children: palette::CHILDREN.iter().map(|c| c.css()).collect(),
        target: palette::TARGET.css(),
        control: palette::CONTROL.css(),
        sight: palette::SIGHT.css(),
        smoothed: palette::SMOOTHED.css(),
    };
    let targets: Vec<PageTarget> = episode
        .targets
        .iter()
        .map(|t| PageTarget {
            pos: cell_units(g, t.position),
            name: t.name.clone(),
            kind: match t.origin {
                TargetOrigin::Control => "control",
                TargetOrigin::Free => "free",
                TargetOrigin::Placed => "placed",
            },
            from: t.placed_at_scan.map_or(1, |k| k + 1),
            sigma_mm: t.smoothed_sigma_m.map(|v| 1e3 * v),
        })
        .collect();
    let mut legend = vec![
        ("parent's path".into(), colours.path.clone()),
        ("the next move".into(), "#d62728".into()),
        ("scan".into(), colours.scan.clone()),
        ("the parent at this scan (square)".into(), "#1b7a1b".into()),
        (
            "candidates by G (green best, grey not eligible; ringed: the next target)".into(),
            "#78c850".into(),
        ),
        ("error ellipse".into(), colours.ellipse.clone()),
    ];
    if !targets.is_empty() {
        legend.push((
            "targets (circled cross) and control points (triangle)".into(),
            colours.target.clone(),
        ));
        legend.push((
            "a station's measurement of a target".into(),
            colours.sight.clone(),
        ));
    }
    if episode.steps.iter().any(|s| s.smoothed_sigma_m.is_some()) {
        legend.push((
            "error plot: smoothed σ (every measurement)".into(),
            colours.smoothed.clone(),
        ));
    }
    for c in 0..children {
        let colour = colours.children[c % colours.children.len()].clone();
        legend.push((format!("child {}, its AND region", c + 1), colour));
    }
    let data = PageData {
        title: title.to_string(),
        subtitle: format!(
            "{} scans \u{b7} coverage {} % \u{b7} parent travel {:.0} m \u{b7} {} \u{b7} {} \u{d7} {} cells of {} m",
            s.scans,
            crate::render::share_percent(s.coverage),
            s.parent_travel_m,
            s.stop_reason.name(),
            g.width,
            g.height,
            g.resolution
        ),
        grid: PageGrid {
            width: g.width,
            height: g.height,
            resolution: g.resolution,
        },
        cells,
        steps,
        targets,
        summary,
        legend,
        colours,
    };
    let json = script_json(&data)?;
    Ok(page_of_data(title, &json))
}

/// The player page of `title` around the data of one episode (as
/// [`episode_page`] makes them, with no `<` in them).
fn page_of_data(title: &str, data: &str) -> String {
    TEMPLATE
        .replace("__TITLE__", &escape(title))
        .replace("__DATA__", data)
}

/// The title of the page of an experiment's episode.
pub fn page_title(experiment: &str, episode: &str) -> String {
    format!("cpsplan experiment {experiment} \u{2014} {episode}")
}

/// What stands just before an episode page's data.
const DATA_START: &str = "<script id=\"data\" type=\"application/json\">";

/// The data of an episode page written by [`episode_page`] (they hold no `<`,
/// so they end at the first `<` after their start); `None` if `page` is not
/// such a page.
pub fn page_data(page: &str) -> Option<&str> {
    let from = page.find(DATA_START)? + DATA_START.len();
    let len = page[from..].find('<')?;
    let data = &page[from..from + len];
    data.starts_with('{').then_some(data)
}

/// The player of [`episode_page`] as a JSON string (no `<` in it) for a page
/// that shows several episodes: their data take the place of `__DATA__` and
/// the page's title that of `__TITLE__`.
pub fn player_template_json() -> Result<String> {
    script_json(&TEMPLATE)
}

/// `data` as JSON to stand inside a `<script>` element: with no `<` in it (no
/// `</script>`, no `<!--`), which in JSON can stand only inside strings, where
/// `\u003c` means the same.
fn script_json(data: &impl Serialize) -> Result<String> {
    Ok(serde_json::to_string(data)?.replace('<', "\\u003c"))
}

/// `text` safe inside HTML (text and attribute values).
pub fn escape(text: &str) -> String {
    text.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn and_regions_become_row_runs_on_a_coarse_grid() {
        let g = GridGeometry::new(300, 200, 0.1, Point::new(0.0, 0.0));
        // A 200 × 10 block from (50, 20).
        let mut cells = Vec::new();
        for y in 20..30 {
            for x in 50..250 {
                cells.push((y * 300 + x) as u32);
            }
        }
        let r = coarse_runs(&g, &cells, 1).unwrap();
        assert_eq!((r.child, r.x0, r.y0), (1, 50, 20));
        assert_eq!(r.scale, 3, "200 cells fit 96 at a scale of 3");
        // Rows 20..30 fall in coarse rows 0..=3, each one run over all 67 columns.
        assert_eq!(r.runs.len(), 4 * 3);
        for (k, run) in r.runs.chunks(3).enumerate() {
            assert_eq!(run, [k as u32, 0, 67]);
        }
        assert!(coarse_runs(&g, &[], 0).is_none());
    }

    #[test]
    fn a_page_gives_back_its_data() {
        let data = script_json(&serde_json::json!({"label": "a </script> b", "k": [1]})).unwrap();
        let page = page_of_data("t <x>", &data);
        assert_eq!(page_data(&page), Some(data.as_str()));
        assert!(page.contains("<title>t &lt;x&gt;</title>"));
        assert_eq!(page_data("<html>no data</html>"), None);
        let not_ours = page_of_data("t", "[1]");
        assert_eq!(
            page_data(&not_ours),
            None,
            "the data of a page are an object"
        );
        let tpl: String = serde_json::from_str(&player_template_json().unwrap()).unwrap();
        assert_eq!(tpl, TEMPLATE);
    }

    #[test]
    fn the_data_cannot_end_their_script_element() {
        let label = "map </script><!-- <b>";
        let json = script_json(&vec![label]).unwrap();
        assert!(!json.contains('<'), "{json}");
        let back: Vec<String> = serde_json::from_str(&json).unwrap();
        assert_eq!(back, [label]);
    }

    #[test]
    fn ellipses_follow_the_covariance() {
        let g = GridGeometry::new(10, 10, 0.1, Point::new(0.0, 0.0));
        // σx = 0.2 m, σy = 0.1 m: 2 and 1 cells, along x.
        let e = ellipse(&g, [[0.04, 0.0], [0.0, 0.01]]).unwrap();
        assert!((e[0] - 2.0).abs() < 1e-9 && (e[1] - 1.0).abs() < 1e-9 && e[2].abs() < 1e-12);
        // Along y.
        let e = ellipse(&g, [[0.01, 0.0], [0.0, 0.04]]).unwrap();
        assert!((e[2].abs() - std::f64::consts::FRAC_PI_2).abs() < 1e-9);
        assert!(ellipse(&g, [[f64::NAN, 0.0], [0.0, 1.0]]).is_none());
    }
}
