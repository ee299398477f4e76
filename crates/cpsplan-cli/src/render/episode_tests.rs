//! Tests of the episode picture on bigger and crowded maps: the crop, the axes,
//! the scan labels, the children's marks, the legend and the larger picture.

use cpsplan::world::builtin::BuiltinMap;
use cpsplan::{run_episode, CellState, Config, Episode, GridGeometry, OccupancyGrid, Point};
use tiny_skia::Pixmap;

use super::canvas::Rgb;
use super::episode::{draw_episode_figure, EpisodeFigure};
use super::journey::child_stands;
use super::layout::world_to_grid_xy;
use super::team::child_look;
use super::*;

/// Two rooms of 12 m × 8 m (split by a wall with a door at x = 6 m) in the middle
/// of a 50 m × 40 m grid that is otherwise solid rock.
fn rooms_in_rock() -> OccupancyGrid {
    let g = GridGeometry::new(500, 400, 0.1, Point::new(-20.0, -15.0));
    let mut grid = OccupancyGrid::filled(g, CellState::Occupied);
    grid.fill_rect(202, 162, 318, 238, CellState::Free);
    grid.fill_rect(260, 160, 263, 240, CellState::Occupied);
    grid.fill_rect(260, 172, 263, 184, CellState::Free);
    grid
}

fn explore(truth: &OccupancyGrid, start: Point, children: usize) -> Episode {
    let mut config = Config::default();
    config.scanner.range = 3.0;
    config.children.count = children;
    run_episode(truth, start, &config, |_| {}).expect("episode runs")
}

/// `ep` with `n` extra scans packed on a spiral of 1.5 m around `centre`.
fn crowded(mut ep: Episode, centre: Point, n: usize) -> Episode {
    let template = ep.steps[ep.steps.len() / 2].clone();
    let last = ep.steps.pop().expect("steps");
    for k in 0..n {
        let a = k as f64 * 0.9;
        let r = 1.5 * (k as f64 / n as f64).sqrt();
        let mut s = template.clone();
        s.position = Point::new(centre.x + r * a.cos(), centre.y + r * a.sin());
        s.movement.cycles.clear();
        s.plan.path = Vec::new();
        ep.steps.push(s);
    }
    ep.steps.push(last);
    for (i, s) in ep.steps.iter_mut().enumerate() {
        s.scan = i + 1;
    }
    ep
}

fn figure(truth: &OccupancyGrid, ep: &Episode) -> EpisodeFigure {
    draw_episode_figure(truth, ep, "test", 1).expect("picture")
}

/// Labels pairwise disjoint, none over another scan's marker, every scan
/// numbered once or counted as omitted.
fn assert_labels_disjoint(fig: &EpisodeFigure, ep: &Episode) {
    let scans = ep.steps.len();
    let labels = &fig.labels.labels;
    for l in labels {
        for (i, s) in ep.steps.iter().enumerate() {
            if !(l.first..=l.last).contains(&i) {
                let (x, y) = fig.frame.layout.world_to_px(s.position);
                let dot = canvas::Rect::new(x - 3.0, y - 3.0, 6.0, 6.0);
                assert_eq!(l.rect.overlap(&dot), 0.0, "{l:?} hides scan {i}");
            }
        }
    }
    for (i, a) in labels.iter().enumerate() {
        for b in &labels[i + 1..] {
            assert_eq!(a.rect.overlap(&b.rect), 0.0, "{a:?} overlaps {b:?}");
        }
    }
    // Every scan is numbered once or counted as omitted.
    let mut numbered = vec![0; scans];
    for l in labels {
        for n in &mut numbered[l.first..=l.last] {
            *n += 1;
        }
    }
    assert!(numbered.iter().all(|&n| n <= 1), "{numbered:?}");
    let unlabelled = numbered.iter().filter(|&&n| n == 0).count();
    assert_eq!(unlabelled, fig.labels.omitted);
}

#[test]
fn episode_picture_crops_to_the_known_area_and_holds_every_scan() {
    let truth = rooms_in_rock();
    let ep = explore(&truth, Point::new(1.55, 6.05), 0);
    let fig = figure(&truth, &ep);
    let g = *truth.geometry();
    let w = fig.window;
    // The rooms (116 × 76 cells) with about 2 m around: far less than the grid.
    assert!(w.width() < 180 && w.height() < 140, "{w:?}");
    assert!(w.x0 > 150 && w.y0 > 110, "{w:?}");
    let map = fig.frame.layout.rect();
    for s in &ep.steps {
        let (x, y) = world_to_grid_xy(&g, s.position);
        assert!(
            x >= w.x0 as f64 + 15.0 && x <= w.x1 as f64 - 15.0,
            "{x} in {w:?}"
        );
        assert!(
            y >= w.y0 as f64 + 15.0 && y <= w.y1 as f64 - 15.0,
            "{y} in {w:?}"
        );
        let (px, py) = fig.frame.layout.world_to_px(s.position);
        assert!(map.contains(&canvas::Rect::new(px, py, 0.0, 0.0)));
    }
    // Every known cell lies in the window.
    let k = ep.knowledge.as_ref().unwrap();
    for (i, &c) in k.cells().iter().enumerate() {
        if c != CellState::Unknown {
            let (x, y) = (i % g.width, i / g.width);
            assert!(x >= w.x0 && x < w.x1 && y >= w.y0 && y < w.y1);
        }
    }
    // A sensible size: the longer side about 1600 px.
    let l = fig.frame.layout;
    assert!(
        (1400..=2000).contains(&l.width_px.max(l.height_px)),
        "{l:?}"
    );
}

#[test]
fn episode_picture_axes_tick_round_metres() {
    let truth = rooms_in_rock();
    let ep = explore(&truth, Point::new(1.55, 6.05), 0);
    let fig = figure(&truth, &ep);
    let axes = &fig.axes;
    assert!(!axes.rotated);
    assert!(axes.step >= 1.0 && axes.step.fract() == 0.0);
    let layout = fig.frame.layout;
    // Bottom ticks: world x at round metres, where they sit.
    assert!(axes.bottom.1.len() >= 3);
    for t in &axes.bottom.1 {
        assert_eq!(t.value % axes.step, 0.0);
        let p = layout.px_to_world(
            layout.x0 as f64 + t.offset as f64,
            (layout.y0 + layout.height_px) as f64,
        );
        assert!((p.x - t.value).abs() < 1e-3, "{t:?} {p:?}");
    }
    // The origin (0, 0) lies in the rooms: drawn and in the legend.
    assert!(axes.bottom.1.iter().any(|t| t.value == 0.0));
    assert!(fig.legend.iter().any(|l| l == "world origin (0, 0)"));
}

#[test]
fn crowded_scan_labels_never_overlap_and_omissions_are_told() {
    let truth = rooms_in_rock();
    let ep = crowded(
        explore(&truth, Point::new(1.55, 6.05), 0),
        Point::new(3.0, 4.0),
        80,
    );
    let scans = ep.steps.len();
    let fig = figure(&truth, &ep);
    assert_labels_disjoint(&fig, &ep);
    // The ends are always numbered.
    let labels = &fig.labels.labels;
    assert!(labels.iter().any(|l| l.first == 0 && l.last == 0));
    assert!(labels.iter().any(|l| l.first == scans - 1));
    // 80 scans within 1.5 m cannot all get their own label: ranges or omissions,
    // and the header says so.
    let note = fig.labels.note(Some("more in map-large.png"));
    assert!(
        fig.labels.in_ranges() > 0 || fig.labels.omitted > 0,
        "{note}"
    );
    if fig.labels.omitted > 0 {
        assert!(note.contains(&format!("labels of {} scans omitted", fig.labels.omitted)));
    }
    if let Some(r) = labels.iter().find(|l| l.last > l.first) {
        assert_eq!(r.text, format!("{}\u{2013}{}", r.first + 1, r.last + 1));
        assert!(note.contains(&r.text), "{note}");
    }
}

#[test]
fn the_large_picture_numbers_more_and_is_only_made_when_needed() {
    let truth = rooms_in_rock();
    let ep = explore(&truth, Point::new(1.55, 6.05), 0);
    if figure(&truth, &ep).labels.omitted == 0 {
        assert!(render_episode_large(&truth, &ep, "t").unwrap().is_none());
    }
    let ep = crowded(ep, Point::new(3.0, 4.0), 80);
    let normal = figure(&truth, &ep);
    assert!(normal.labels.omitted > 0);
    let large = render_episode_large(&truth, &ep, "t")
        .unwrap()
        .expect("a larger picture");
    let pic = Pixmap::decode_png(&large).unwrap();
    assert!(pic.width() > normal.frame.canvas.pixmap.width());
    // The memory estimate before the run holds the larger canvas and its PNG;
    // without the larger picture, the normal one.
    let canvas = |p: &Pixmap| u64::from(p.width()) * u64::from(p.height()) * 4;
    let g = truth.geometry();
    assert!(pictures_peak_bytes(g, true) >= canvas(&pic) + large.len() as u64);
    let (png, again) = render_episode_pictures(&truth, &ep, "t").unwrap();
    assert_eq!(again.as_deref(), Some(&large[..]));
    let small = Pixmap::decode_png(&png).unwrap();
    assert!(pictures_peak_bytes(g, false) >= canvas(&small) + png.len() as u64);
    assert!(pictures_peak_bytes(g, false) < pictures_peak_bytes(g, true));
    let zoomed = draw_episode_figure(&truth, &ep, "t", 2).unwrap();
    assert!(zoomed.labels.omitted < normal.labels.omitted);
    assert_labels_disjoint(&zoomed, &ep);
}

fn has_colour_near(p: &Pixmap, (x, y): (f32, f32), radius: i32, c: Rgb) -> bool {
    (-radius..=radius).any(|dy| {
        (-radius..=radius).any(|dx| {
            let (px, py) = (x.round() as i32 + dx, y.round() as i32 + dy);
            u32::try_from(px)
                .ok()
                .zip(u32::try_from(py).ok())
                .and_then(|(px, py)| p.pixel(px, py))
                .is_some_and(|q| (q.red(), q.green(), q.blue()) == (c.0, c.1, c.2))
        })
    })
}

#[test]
fn children_are_drawn_apart_and_the_legend_lists_what_is_drawn() {
    let mut config = Config::default();
    config.children.count = 2;
    config.mission.max_scans = 4;
    let truth = BuiltinMap::Site.generate(0);
    let ep = run_episode(&truth, BuiltinMap::Site.default_start(), &config, |_| {})
        .expect("episode runs");
    let fig = figure(&truth, &ep);
    let legend = &fig.legend;
    for n in 0..2 {
        let name = format!("child {} path and stands", n + 1);
        assert!(legend.contains(&name), "{legend:?}");
        // Each standing place shows the child's colour.
        let colour = child_look(n).colour;
        for p in child_stands(&ep, n) {
            let at = fig.frame.layout.world_to_px(p);
            assert!(
                has_colour_near(&fig.frame.canvas.pixmap, at, 2, colour),
                "child {n} at {p:?}"
            );
        }
    }
    assert!(!legend.iter().any(|l| l.starts_with("child 3")));
    assert!(legend.contains(&"parent".to_owned()));
    assert!(!legend.contains(&"trajectory".to_owned()));

    // Without children: no child entries, the parent's path is "trajectory"; no
    // missed cells in a fully explored map, so no "missed" entry.
    let truth = rooms_in_rock();
    let ep = explore(&truth, Point::new(1.55, 6.05), 0);
    let fig = figure(&truth, &ep);
    assert!(
        !fig.legend.iter().any(|l| l.starts_with("child")),
        "{:?}",
        fig.legend
    );
    assert!(fig.legend.contains(&"trajectory".to_owned()));
    assert_eq!(fig.legend.contains(&"end".to_owned()), ep.steps.len() > 1);
    assert_eq!(
        fig.legend.contains(&"missed".to_owned()),
        ep.summary.coverage < 1.0
    );
    assert!(!fig.legend.iter().any(|l| l.starts_with("subgoal")));
}

/// A map turned by a half turn (ROS yaw π, or the Stata basement's 3.14) is
/// drawn as RViz shows it: world x growing to the right, y upwards; only what
/// is left of the yaw after the quarter turns earns a compass. A yaw far from
/// every quarter turn keeps the grid's frame and the compass.
#[test]
fn quarter_turned_grids_are_drawn_upright_and_others_get_a_compass() {
    for (yaw, upright, compass) in [
        (std::f64::consts::PI, true, false),
        (std::f64::consts::PI - 0.0016, true, true),
        (std::f64::consts::FRAC_PI_2, true, false),
        (0.7, false, true),
    ] {
        let mut truth = rooms_in_rock();
        let mut g = *truth.geometry();
        g.yaw = yaw;
        g.origin = Point::new(30.0, 25.0);
        truth = OccupancyGrid::from_cells(g, truth.cells().to_vec()).expect("same size");
        let start = g.cell_center(cpsplan::Cell::new(215, 200));
        let ep = explore(&truth, start, 0);
        let fig = figure(&truth, &ep);
        assert_eq!(fig.axes.rotated, compass, "yaw {yaw}");
        let bottom: Vec<f64> = fig.axes.bottom.1.iter().map(|t| t.value).collect();
        let left: Vec<f64> = fig.axes.left.1.iter().map(|t| t.value).collect();
        assert!(bottom.iter().all(|v| v % fig.axes.step == 0.0));
        if upright {
            assert_eq!(fig.axes.bottom.0, super::axes::Coord::X, "yaw {yaw}");
            assert!(
                bottom.windows(2).all(|w| w[1] > w[0]),
                "yaw {yaw}: {bottom:?}"
            );
            assert!(left.windows(2).all(|w| w[1] > w[0]), "yaw {yaw}: {left:?}");
        }
    }
}
