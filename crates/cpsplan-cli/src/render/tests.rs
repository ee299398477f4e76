use cpsplan::{run_episode, Cell, CellState, Config, Episode, GridGeometry, OccupancyGrid, Point};
use tiny_skia::Pixmap;

use super::*;

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

    // A pixel halfway along the longest leg between two scans far apart.
    let (i, leg) = ep.steps[..ep.steps.len() - 1]
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.plan.path_length_m.total_cmp(&b.1.plan.path_length_m))
        .unwrap();
    assert!(
        ep.steps[i].position.distance(ep.steps[i + 1].position) > 1.5,
        "scans {} and {} are close",
        i + 1,
        i + 2
    );
    let path = &leg.plan.path;
    let seg = path
        .windows(2)
        .max_by(|a, b| a[0].distance(a[1]).total_cmp(&b[0].distance(b[1])))
        .unwrap();
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
