use cpsplan::{run_episode, Cell, CellState, Config, Episode, GridGeometry, OccupancyGrid, Point};
use tiny_skia::Pixmap;

use super::canvas::Rgb;
use super::episode::draw_episode;
use super::layout::{world_to_grid_xy, MapLayout};
use super::map::draw_map;
use super::*;
use super::{chrome, palette};

/// A 12 m × 8 m room (120 × 80 cells) split by a wall at x = 6 m with a door.
fn two_rooms() -> OccupancyGrid {
    let g = GridGeometry::new(120, 80, 0.1, Point::new(0.0, 0.0));
    let mut grid = OccupancyGrid::filled(g, CellState::Occupied);
    grid.fill_rect(2, 2, 118, 78, CellState::Free);
    grid.fill_rect(60, 0, 63, 80, CellState::Occupied);
    grid.fill_rect(60, 12, 63, 24, CellState::Free);
    grid
}

fn episode(truth: &OccupancyGrid) -> Episode {
    let mut config = Config::default();
    // A short range makes the parent move several times in the small map.
    config.scanner.range = 3.0;
    run_episode(truth, Point::new(1.55, 6.05), &config, |_| {}).expect("episode runs")
}

fn rgb_at(p: &Pixmap, x: f32, y: f32) -> (u8, u8, u8) {
    let c = p
        .pixel(x.round() as u32, y.round() as u32)
        .expect("pixel inside the picture");
    (c.red(), c.green(), c.blue())
}

fn close(a: (u8, u8, u8), b: Rgb, tol: i32) -> bool {
    (i32::from(a.0) - i32::from(b.0)).abs() <= tol
        && (i32::from(a.1) - i32::from(b.1)).abs() <= tol
        && (i32::from(a.2) - i32::from(b.2)).abs() <= tol
}

/// Whether a pixel within `radius` of (`x`, `y`) has colour `c`.
fn near(p: &Pixmap, x: f32, y: f32, radius: i32, c: Rgb) -> bool {
    (-radius..=radius).any(|dy| {
        (-radius..=radius).any(|dx| close(rgb_at(p, x + dx as f32, y + dy as f32), c, 12))
    })
}

#[test]
fn episode_picture_decodes_and_shows_map_and_trajectory() {
    let truth = two_rooms();
    let ep = episode(&truth);
    assert!(ep.steps.len() >= 3, "{} steps", ep.steps.len());
    let frame = draw_episode(&truth, &ep, "two rooms").unwrap();
    let png = render_episode(&truth, &ep, "two rooms").unwrap();
    let pic = Pixmap::decode_png(&png).unwrap();
    assert_eq!(pic.width(), frame.canvas.pixmap.width());
    assert_eq!(pic.height(), frame.canvas.pixmap.height());
    let layout = frame.layout;
    // 120 cells along the longer side: 13 px per cell.
    assert_eq!((layout.width_px, layout.height_px), (1560, 1040));
    assert!(pic.width() >= 1560 && pic.height() > 1040);

    let g = *truth.geometry();
    let knowledge = ep.knowledge.as_ref().unwrap();
    let centre = |c: Cell| layout.world_to_px(g.cell_center(c));

    // A free cell in the far corner of the right room, seen by some scan.
    let free = Cell::new(115, 75);
    assert_eq!(knowledge.get(free), CellState::Free);
    let (x, y) = centre(free);
    assert!(close(rgb_at(&pic, x, y), palette::FREE, 0));
    // The dividing wall.
    let wall = Cell::new(60, 60);
    assert_eq!(knowledge.get(wall), CellState::Occupied);
    let (x, y) = centre(wall);
    assert!(close(rgb_at(&pic, x, y), palette::OCCUPIED, 0));
    // The outer border is solid and never seen from inside on its outer side.
    let (x, y) = centre(Cell::new(0, 0));
    assert!(close(rgb_at(&pic, x, y), palette::UNKNOWN, 0));

    // The start marker.
    let (sx, sy) = layout.world_to_px(ep.start);
    assert!(close(rgb_at(&pic, sx, sy), palette::START, 12));
    // The last scan marker.
    let (ex, ey) = layout.world_to_px(ep.steps.last().unwrap().position);
    assert!(close(rgb_at(&pic, ex, ey), palette::END, 12));

    // A pixel halfway along the longest straight leg the parent drove, away
    // from every scan marker.
    let paths: Vec<Vec<Point>> = ep.steps.iter().map(|s| s.driven_path()).collect();
    let middle =
        |seg: &[Point]| Point::new((seg[0].x + seg[1].x) / 2.0, (seg[0].y + seg[1].y) / 2.0);
    let seg = paths
        .iter()
        .flat_map(|p| p.windows(2))
        .filter(|seg| {
            ep.steps
                .iter()
                .all(|s| s.position.distance(middle(seg)) > 0.7)
        })
        .max_by(|a, b| a[0].distance(a[1]).total_cmp(&b[0].distance(b[1])))
        .expect("a leg away from the scans");
    assert!(seg[0].distance(seg[1]) > 1.0, "{seg:?}");
    let mid = Point::new((seg[0].x + seg[1].x) / 2.0, (seg[0].y + seg[1].y) / 2.0);
    let (mx, my) = layout.world_to_px(mid);
    assert!(near(&pic, mx, my, 1, palette::TRAJECTORY));
}

#[test]
fn missed_space_is_tinted() {
    let truth = two_rooms();
    let mut ep = episode(&truth);
    // Forget a block of the right room and one of its walls, as if never scanned.
    let k = ep.knowledge.as_mut().unwrap();
    k.fill_rect(100, 40, 110, 50, CellState::Unknown);
    k.fill_rect(118, 40, 120, 50, CellState::Unknown);
    let frame = draw_episode(&truth, &ep, "missed").unwrap();
    let g = *truth.geometry();
    let px = |c: Cell| {
        let (x, y) = frame.layout.world_to_px(g.cell_center(c));
        rgb_at(&frame.canvas.pixmap, x, y)
    };
    assert!(close(px(Cell::new(105, 45)), palette::MISSED, 0));
    assert!(close(px(Cell::new(118, 45)), palette::MISSED_WALL, 0));
    // Solid rock behind the wall is not counted as missed.
    assert!(close(px(Cell::new(119, 45)), palette::UNKNOWN, 0));
}

#[test]
fn episode_without_knowledge_draws_truth() {
    let truth = two_rooms();
    let mut ep = episode(&truth);
    ep.knowledge = None;
    let frame = draw_episode(&truth, &ep, "truth only").unwrap();
    let g = *truth.geometry();
    let (x, y) = frame.layout.world_to_px(g.cell_center(Cell::new(0, 0)));
    assert!(close(
        rgb_at(&frame.canvas.pixmap, x, y),
        palette::OCCUPIED,
        0
    ));
}

#[test]
fn mismatched_knowledge_is_an_error() {
    let truth = two_rooms();
    let mut ep = episode(&truth);
    ep.knowledge = Some(OccupancyGrid::filled(
        GridGeometry::new(10, 10, 0.1, Point::default()),
        CellState::Unknown,
    ));
    assert!(matches!(
        render_episode(&truth, &ep, "x"),
        Err(RenderError::GeometryMismatch { .. })
    ));
}

#[test]
fn map_preview_colours_and_size() {
    let mut grid = two_rooms();
    grid.fill_rect(0, 0, 10, 10, CellState::Unknown);
    let png = render_map(&grid, "preview").unwrap();
    let pic = Pixmap::decode_png(&png).unwrap();
    let frame = draw_map(&grid, "preview").unwrap();
    assert_eq!(
        (pic.width(), pic.height()),
        (frame.canvas.pixmap.width(), frame.canvas.pixmap.height())
    );
    let g = *grid.geometry();
    let px = |c: Cell| {
        let (x, y) = frame.layout.world_to_px(g.cell_center(c));
        rgb_at(&pic, x, y)
    };
    assert!(close(px(Cell::new(30, 40)), palette::FREE, 0));
    assert!(close(px(Cell::new(61, 40)), palette::OCCUPIED, 0));
    assert!(close(px(Cell::new(5, 5)), palette::UNKNOWN, 0));
}

/// The map preview (and so `grid --preview`, `bound` and the step figures,
/// which share its frame) carries world axes: a tick under the map's bottom
/// edge at a round x, and one left of its left edge at a round y, a world
/// quarter turn included.
#[test]
fn previews_carry_world_axes() {
    for yaw in [0.0, std::f64::consts::PI] {
        let mut g = GridGeometry::new(100, 80, 0.1, Point::new(0.0, 0.0));
        g.yaw = yaw;
        let grid = OccupancyGrid::filled(g, CellState::Free);
        let frame = draw_map(&grid, "axes").unwrap();
        let l = frame.layout;
        let pic = &frame.canvas.pixmap;
        let (min_x, min_y) = if yaw == 0.0 {
            (0.0, 0.0)
        } else {
            (-10.0, -8.0)
        };
        let (x, _) = l.world_to_px(Point::new(min_x + 4.0, min_y + 1.0));
        let (_, y) = l.world_to_px(Point::new(min_x + 1.0, min_y + 4.0));
        let below = (l.y0 + l.height_px + 3) as f32;
        let left = (l.x0 - 3) as f32;
        assert!(
            near(pic, x, below, 2, palette::MUTED_TEXT),
            "yaw {yaw}: no x tick"
        );
        assert!(
            near(pic, left, y, 2, palette::MUTED_TEXT),
            "yaw {yaw}: no y tick"
        );
        // World x grows to the right, y upwards.
        let (a, b) = (
            l.world_to_px(Point::new(min_x + 1.0, min_y + 1.0)),
            l.world_to_px(Point::new(min_x + 2.0, min_y + 2.0)),
        );
        assert!(b.0 > a.0 && b.1 < a.1, "yaw {yaw}: {a:?} {b:?}");
    }
}

#[test]
fn huge_grids_are_reduced_and_keep_thin_walls() {
    let g = GridGeometry::new(6000, 90, 0.05, Point::default());
    let mut grid = OccupancyGrid::filled(g, CellState::Free);
    grid.fill_rect(3001, 0, 3002, 90, CellState::Occupied);
    let frame = draw_map(&grid, "long").unwrap();
    let layout = frame.layout;
    assert!(layout.width_px <= 1800, "{}", layout.width_px);
    let (x, y) = layout.world_to_px(g.cell_center(Cell::new(3001, 45)));
    assert!(close(
        rgb_at(&frame.canvas.pixmap, x.floor(), y),
        palette::OCCUPIED,
        0
    ));
}

#[test]
fn bad_maps_are_errors_not_panics() {
    let empty = OccupancyGrid::filled(
        GridGeometry::new(0, 5, 0.1, Point::default()),
        CellState::Free,
    );
    assert!(matches!(
        render_map(&empty, "e"),
        Err(RenderError::EmptyMap { .. })
    ));
    let bad = OccupancyGrid::filled(
        GridGeometry::new(5, 5, f64::NAN, Point::default()),
        CellState::Free,
    );
    assert!(matches!(
        render_map(&bad, "b"),
        Err(RenderError::BadResolution(_))
    ));
}

#[test]
fn rotated_grids_use_the_grid_frame() {
    let mut g = GridGeometry::new(40, 20, 0.5, Point::new(3.0, -2.0));
    g.yaw = 0.6;
    let c = Cell::new(7, 4);
    let (x, y) = world_to_grid_xy(&g, g.cell_center(c));
    assert!((x - 7.5).abs() < 1e-9 && (y - 4.5).abs() < 1e-9);
}

#[test]
fn odd_titles_and_long_titles_render() {
    let grid = two_rooms();
    let title = "Büro \u{2014} 日本 ".repeat(40);
    assert!(render_map(&grid, &title).is_ok());
}

#[test]
fn scale_keeps_the_longer_side_near_1600_px() {
    for (cells, px) in [
        (120, 1560),
        (800, 1600),
        (601, 1803),
        (1066, 1066),
        (1500, 1500),
        (2400, 2400),
        (4000, 1334),
        (10, 1600),
    ] {
        let l = MapLayout::new(&GridGeometry::new(cells, 7, 0.1, Point::default()));
        assert_eq!(l.width_px, px, "{cells} cells");
    }
}

// ---------------------------------------------------------------------------------
// Step figures and subgoal markers.

use cpsplan::mission::{CycleRecord, Step};
use cpsplan::world::builtin::BuiltinMap;

use self::step::{and_region_colour, draw_step, score_colour, StepView, Window};

/// The first `scans` steps of the built-in site with two children, each with the
/// knowledge map it planned on.
fn site_steps(scans: usize) -> (Config, Vec<(Step, OccupancyGrid)>) {
    let mut config = Config::default();
    config.children.count = 2;
    config.mission.max_scans = scans;
    let truth = BuiltinMap::Site.generate(0);
    let mut steps = Vec::new();
    cpsplan::run_episode_with(
        &truth,
        BuiltinMap::Site.default_start(),
        &config,
        |step, knowledge| steps.push((step.clone(), knowledge.clone())),
    )
    .expect("episode runs");
    (config, steps)
}

/// Every marker position a step figure draws, canvas pixels.
fn marker_pixels(layout: &MapLayout, step: &Step) -> Vec<(f32, f32)> {
    let mut points: Vec<Point> = step.plan.candidates.iter().map(|c| c.position).collect();
    points.push(step.position);
    points.extend(step.children.iter().copied());
    for cycle in &step.movement.cycles {
        points.push(cycle.parent_to);
        points.extend(cycle.children.iter().flat_map(|c| [c.from, c.to]));
    }
    points.iter().map(|&p| layout.world_to_px(p)).collect()
}

#[test]
fn step_figure_shows_and_regions_and_scored_candidates() {
    let (config, steps) = site_steps(3);
    let (step, knowledge) = &steps[1];
    assert_eq!(step.scan, 2);
    assert!(
        !step.movement.cycles.is_empty(),
        "step 2 moved by no CPS cycle"
    );
    let view = StepView::from(step);
    let fig = draw_step(knowledge, &view, &config, "step 2").unwrap();
    let png = render_step(knowledge, &view, &config, "step 2").unwrap();
    let pic = Pixmap::decode_png(&png).unwrap();
    let canvas = &fig.frame.canvas.pixmap;
    assert_eq!(
        (pic.width(), pic.height()),
        (canvas.width(), canvas.height())
    );

    // The window holds the parent, its target and every cycle, and is drawn at the
    // scale rule of the other pictures (a whole number of pixels per cell nearest
    // to a longer side of 1600 px: from 1067 to 2000 px).
    let layout = fig.frame.layout;
    let w = fig.window;
    let g = *knowledge.geometry();
    let target = &step.plan.candidates[step.movement.target.unwrap()];
    for p in [step.position, target.position] {
        let c = g.world_to_cell(p).unwrap();
        assert!((w.x0..w.x1).contains(&c.x) && (w.y0..w.y1).contains(&c.y));
    }
    // Early in the run the site is only partly known: the window is a part of it.
    assert!((w.x1 - w.x0) * (w.y1 - w.y0) < g.len() / 2, "{w:?}");
    let longest = layout.width_px.max(layout.height_px);
    let rule = MapLayout::new(&w.geometry(&g));
    assert_eq!(longest, rule.width_px.max(rule.height_px));
    assert!((1067..=2000).contains(&longest), "{longest} px");
    assert_eq!(
        layout.width_px as usize,
        (w.x1 - w.x0) * layout.px_per_cell / layout.cells_per_px
    );
    assert!(pic.width() as i64 > layout.width_px && pic.height() as i64 > layout.height_px);

    // The AND region: known-free cells inside it are tinted, those outside are not.
    let cell_px = |i: usize| {
        let ww = w.x1 - w.x0;
        let c = Cell::new(w.x0 + i % ww, w.y0 + i / ww);
        (c, layout.world_to_px(g.cell_center(c)))
    };
    let markers = marker_pixels(&layout, step);
    let clear_of_markers =
        |p: (f32, f32)| markers.iter().all(|m| (m.0 - p.0).hypot(m.1 - p.1) > 30.0);
    let (mut inside, mut tinted, mut outside, mut wrongly) = (0, 0, 0, 0);
    let tint = and_region_colour(1);
    for (i, &level) in fig.levels.iter().enumerate() {
        let (cell, (x, y)) = cell_px(i);
        if knowledge.get(cell) != CellState::Free || !clear_of_markers((x, y)) {
            continue;
        }
        let here = rgb_at(&pic, x, y);
        if level == 1 {
            inside += 1;
            tinted += usize::from(close(here, tint, 0));
        } else if level == 0 {
            outside += 1;
            wrongly += usize::from(close(here, tint, 0));
        }
    }
    assert!(inside > 1000, "{inside} free cells in the AND region");
    assert!(
        tinted * 10 >= inside * 9,
        "{tinted} of {inside} AND-region cells tinted"
    );
    assert!(outside > 1000);
    assert!(wrongly * 200 <= outside, "{wrongly} cells tinted outside");
    // The tint is the one the legend shows, and differs from free space.
    assert_ne!(tint, palette::FREE);

    // Candidates: a marker of the score's colour at every eligible candidate clear
    // of the other markers; the scores span the ramp.
    let eligible: Vec<&cpsplan::parent::Candidate> =
        step.plan.candidates.iter().filter(|c| c.eligible).collect();
    let lo = eligible.iter().map(|c| c.g).fold(f64::INFINITY, f64::min);
    let hi = eligible
        .iter()
        .map(|c| c.g)
        .fold(f64::NEG_INFINITY, f64::max);
    assert!(hi > lo, "all candidates score alike");
    let mut checked = Vec::new();
    for c in &eligible {
        let (x, y) = layout.world_to_px(c.position);
        let others = markers
            .iter()
            .filter(|m| (m.0 - x).hypot(m.1 - y) < 25.0)
            .count();
        if others > 1 {
            continue;
        }
        let colour = score_colour(c.g, lo, hi);
        assert!(
            close(rgb_at(&pic, x, y), colour, 3),
            "candidate G {} at {:?}: {:?} is not {colour:?}",
            c.g,
            c.position,
            rgb_at(&pic, x, y)
        );
        checked.push(colour);
    }
    assert!(
        checked.len() >= 2,
        "only {} candidates checked",
        checked.len()
    );
    assert!(checked.iter().any(|&c| c != checked[0]));
    // The target is ringed in dark text colour.
    let (tx, ty) = layout.world_to_px(target.position);
    let ring = style_ring_radius(fig.frame.style);
    assert!(near(&pic, tx + ring, ty, 1, palette::TEXT));
}

/// Where the target's ring runs, pixels from the marker's centre.
fn style_ring_radius(style: chrome::Style) -> f32 {
    style.marker_radius() + 2.5 + style.line_width()
}

/// A step whose single cycle is split in two at a point of the parent's path, as if
/// a subgoal had been retrieved there; returns the subgoal.
fn with_subgoal(step: &mut Step) -> Point {
    let cycle = step.movement.cycles[0].clone();
    let mid = cycle.parent_path[cycle.parent_path.len() / 2];
    let first = CycleRecord {
        parent_to: mid,
        parent_path: cycle.parent_path[..=cycle.parent_path.len() / 2].to_vec(),
        ..cycle.clone()
    };
    let second = CycleRecord {
        parent_from: mid,
        parent_path: cycle.parent_path[cycle.parent_path.len() / 2..].to_vec(),
        ..cycle
    };
    step.movement.cycles = vec![first, second];
    step.movement.subgoal_retrieval = true;
    mid
}

#[test]
fn step_figure_numbers_subgoals_and_tints_later_cycles_lighter() {
    let (config, steps) = site_steps(2);
    let (mut step, knowledge) = steps[0].clone();
    assert!(!step.movement.cycles.is_empty());
    let subgoal = with_subgoal(&mut step);
    let fig = draw_step(&knowledge, &StepView::from(&step), &config, "subgoal").unwrap();
    let pic = &fig.frame.canvas.pixmap;
    let (x, y) = fig.frame.layout.world_to_px(subgoal);
    assert!(close(rgb_at(pic, x, y), palette::SUBGOAL, 3));
    // Both cycles have AND regions; the second's own cells are lighter.
    assert!(fig.levels.contains(&1) && fig.levels.contains(&2));
    let (c1, c2) = (and_region_colour(1), and_region_colour(2));
    let darkness = |c: Rgb| 765 - (u32::from(c.0) + u32::from(c.1) + u32::from(c.2));
    assert!(darkness(c1) > darkness(c2) && darkness(c2) > 0);
}

#[test]
fn step_figure_without_children_draws_the_planned_path() {
    let truth = two_rooms();
    let mut config = Config::default();
    config.scanner.range = 3.0;
    config.children.count = 0;
    let mut captured = None;
    cpsplan::run_episode_with(&truth, Point::new(1.55, 6.05), &config, |step, k| {
        if captured.is_none() && step.plan.path.len() >= 2 {
            captured = Some((step.clone(), k.clone()));
        }
    })
    .unwrap();
    let (step, knowledge) = captured.expect("a step with a path");
    let fig = draw_step(&knowledge, &StepView::from(&step), &config, "alone").unwrap();
    // A small map is drawn whole.
    assert_eq!(fig.window, Window::whole_of(knowledge.geometry()));
    assert!(fig.levels.iter().all(|&l| l == 0));
    let path = &step.plan.path;
    let seg = path
        .windows(2)
        .max_by(|a, b| a[0].distance(a[1]).total_cmp(&b[0].distance(b[1])))
        .unwrap();
    let mid = Point::new((seg[0].x + seg[1].x) / 2.0, (seg[0].y + seg[1].y) / 2.0);
    let (mx, my) = fig.frame.layout.world_to_px(mid);
    assert!(near(
        &fig.frame.canvas.pixmap,
        mx,
        my,
        1,
        palette::TRAJECTORY
    ));
}

#[test]
fn step_window_crops_large_maps_around_the_action() {
    let g = GridGeometry::new(2000, 1500, 0.1, Point::new(-10.0, 5.0));
    let pts = [(100.0, 100.0), (300.0, 180.0)];
    let w = Window::around(&g, pts.into_iter(), None, 4.0, 20.0);
    // 4 m (40 cells) of margin around the 200 × 80 cells of points; the height
    // grown to the 20 m minimum about the points' centre.
    assert_eq!((w.x0, w.y0, w.x1, w.y1), (60, 40, 340, 240));
    // A tall group of points: the width grown to 1.25 times the height.
    let tall = [(500.0, 500.0), (520.0, 800.0)];
    let w = Window::around(&g, tall.into_iter(), None, 4.0, 20.0);
    assert_eq!((w.y0, w.y1), (460, 840));
    assert_eq!((w.x0, w.x1), (272, 748));
    // Widened only as far as the margin beyond the known part of the map.
    let known = Window {
        x0: 450,
        y0: 400,
        x1: 600,
        y1: 900,
    };
    let w = Window::around(&g, tall.into_iter(), Some(known), 4.0, 20.0);
    assert_eq!((w.x0, w.x1, w.y0, w.y1), (410, 640, 460, 840));
    // Near an edge the window is shifted inside the grid, and kept landscape.
    let corner = [(5.0, 5.0), (50.0, 120.0)];
    let w = Window::around(&g, corner.into_iter(), None, 4.0, 20.0);
    assert_eq!((w.x0, w.y0), (0, 0));
    assert!(
        w.y1 >= 160 && w.x1 as f64 >= 1.25 * w.y1 as f64 - 1.0,
        "{w:?}"
    );
    assert!(w.x1 as f64 <= 1.8 * w.y1 as f64 + 1.0);
    // Spread over most of the map: the whole map.
    let spread = [(10.0, 10.0), (1990.0, 1490.0)];
    assert_eq!(
        Window::around(&g, spread.into_iter(), None, 4.0, 20.0),
        Window::whole_of(&g)
    );
    // Nothing finite to frame: the whole map.
    let none = [(f64::NAN, 1.0)];
    assert_eq!(
        Window::around(&g, none.into_iter(), None, 4.0, 20.0),
        Window::whole_of(&g)
    );
}

#[test]
fn episode_picture_marks_intermediate_subgoals() {
    let mut config = Config::default();
    config.children.count = 2;
    config.mission.max_scans = 3;
    let truth = BuiltinMap::Site.generate(0);
    let mut ep = run_episode(&truth, BuiltinMap::Site.default_start(), &config, |_| {})
        .expect("episode runs");
    assert_eq!(ep.steps.len(), 3);
    let subgoal = with_subgoal(&mut ep.steps[0]);
    // The last step's move is not driven: its subgoals are not drawn.
    let unused = with_subgoal(&mut ep.steps[2]);
    assert_eq!(episode::subgoals(&ep), vec![subgoal]);
    let frame = draw_episode(&truth, &ep, "subgoals").unwrap();
    let (x, y) = frame.layout.world_to_px(subgoal);
    assert!(close(
        rgb_at(&frame.canvas.pixmap, x, y),
        palette::SUBGOAL,
        3
    ));
    let (x, y) = frame.layout.world_to_px(unused);
    assert!(!near(&frame.canvas.pixmap, x, y, 2, palette::SUBGOAL));
}

#[test]
fn score_ramp_runs_from_pale_to_dark() {
    let lo = score_colour(1.0, 1.0, 5.0);
    let hi = score_colour(5.0, 1.0, 5.0);
    assert_eq!(lo, palette::SCORE_RAMP[0]);
    assert_eq!(hi, palette::SCORE_RAMP[4]);
    assert_eq!(score_colour(3.0, 1.0, 5.0), palette::SCORE_RAMP[2]);
    // Equal scores take the top colour; out-of-range scores are clamped.
    assert_eq!(score_colour(2.0, 2.0, 2.0), palette::SCORE_RAMP[4]);
    assert_eq!(score_colour(-9.0, 1.0, 5.0), palette::SCORE_RAMP[0]);
}
