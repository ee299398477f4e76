//! `office`: an office floor of 80 m × 60 m.
//!
//! Layout, from south to north: a band of rooms 9 m deep; the main corridor (2.5–3 m,
//! the full width of the building, always around y = 11 m so that the start lies at
//! its west end); a 33–37 m deep middle zone; a second long corridor (2–2.6 m); a
//! band of rooms 8–11 m deep. The middle zone holds two or three blocks, each a cross
//! corridor (2–2.6 m) joining both long corridors with a column of rooms 5–9 m deep
//! on each side, and one open-plan hall with a grid of pillars and desk islands.
//! Rooms are 4–12 m wide; each has a door of 1.2–1.6 m to its corridor, and some
//! have a second door to a neighbouring room or the hall. Some rooms hold a table or
//! cabinet standing at least 1.3 m from every wall. Exterior walls are 0.3 m thick,
//! interior walls 0.2 m.

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::{partition, Canvas, Rect, HEIGHT, WIDTH};
use crate::geom::Point;

/// Start: the west end of the main corridor.
pub(super) const START: Point = Point::new(2.5, 11.0);

/// Exterior wall thickness, cells.
const EXT: i64 = 3;
/// Interior wall thickness, cells.
const WALL: i64 = 2;
/// Door widths, cells (1.2–1.6 m).
const DOOR: (i64, i64) = (12, 16);
/// Least distance from a door to the corner of its wall, cells.
const DOOR_MARGIN: i64 = 4;
/// Room sizes along a corridor, cells (4–12 m).
const ROOM: (i64, i64) = (40, 120);
/// Least free gap around a free-standing obstacle, cells (1.3 m).
const CLEAR: i64 = 13;
/// Width range of the open-plan hall, cells.
const HALL: (i64, i64) = (160, 450);
/// Chance that two neighbouring rooms get a door between them.
const P_SECOND_DOOR: f64 = 0.3;
/// Chance that a room holds free-standing furniture.
const P_FURNITURE: f64 = 0.4;

/// Which wall of a room its corridor door is in.
#[derive(Clone, Copy)]
enum Side {
    North,
    South,
    East,
    West,
}

/// A room: its free interior and the wall facing its corridor (`None` for the hall,
/// whose doors are made separately).
struct Room {
    rect: Rect,
    corridor: Option<Side>,
}

/// One vertical segment of the middle zone.
#[derive(Clone, Copy)]
enum Segment {
    /// Rooms `left` deep, a cross corridor `corridor` wide, rooms `right` deep.
    Block {
        left: i64,
        corridor: i64,
        right: i64,
    },
    /// The open-plan hall.
    Hall,
}

impl Segment {
    fn width(&self, hall: i64) -> i64 {
        match *self {
            Segment::Block {
                left,
                corridor,
                right,
            } => left + WALL + corridor + WALL + right,
            Segment::Hall => hall,
        }
    }
}

pub(super) fn generate(seed: u64) -> Canvas {
    let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x0FF1_CE00_5EED_0001);
    let mut canvas = Canvas::solid();
    let (x0, x1) = (EXT, WIDTH as i64 - EXT);
    let (y0, y1) = (EXT, HEIGHT as i64 - EXT);

    // Main corridor: its edges stay within 9.5–10.0 m and 12.0–13.0 m of the
    // bottom, so START (y = 11 m) always has 1 m of clearance.
    let ya0 = rng.random_range(95..=99);
    let wa = rng.random_range((121 - ya0).max(25)..=30);
    let main = Rect::new(x0, ya0, x1, ya0 + wa);
    let north_depth = rng.random_range(80..=110);
    let yn0 = y1 - north_depth;
    let wb = rng.random_range(20..=26);
    let second = Rect::new(x0, yn0 - WALL - wb, x1, yn0 - WALL);
    let (ym0, ym1) = (main.y1 + WALL, second.y0 - WALL);
    canvas.fill(main, true);
    canvas.fill(second, true);

    let mut rooms = Vec::new();
    for (a, b) in partition(&mut rng, x0, x1, ROOM.0, ROOM.1, WALL) {
        rooms.push(Room {
            rect: Rect::new(a, y0, b, main.y0 - WALL),
            corridor: Some(Side::North),
        });
    }
    for (a, b) in partition(&mut rng, x0, x1, ROOM.0, ROOM.1, WALL) {
        rooms.push(Room {
            rect: Rect::new(a, yn0, b, y1),
            corridor: Some(Side::South),
        });
    }

    let (segments, hall_width) = middle_segments(&mut rng, x1 - x0);
    let mut hall = None;
    let mut x = x0;
    for seg in segments {
        let w = seg.width(hall_width);
        match seg {
            Segment::Hall => {
                let r = Rect::new(x, ym0, x + w, ym1);
                hall = Some(r);
                rooms.push(Room {
                    rect: r,
                    corridor: None,
                });
            }
            Segment::Block {
                left,
                corridor,
                right,
            } => {
                let cx0 = x + left + WALL;
                let cx1 = cx0 + corridor;
                canvas.fill(Rect::new(cx0, main.y1, cx1, second.y0), true);
                for (a, b) in partition(&mut rng, ym0, ym1, ROOM.0, ROOM.1, WALL) {
                    rooms.push(Room {
                        rect: Rect::new(x, a, x + left, b),
                        corridor: Some(Side::East),
                    });
                }
                for (a, b) in partition(&mut rng, ym0, ym1, ROOM.0, ROOM.1, WALL) {
                    rooms.push(Room {
                        rect: Rect::new(cx1 + WALL, a, cx1 + WALL + right, b),
                        corridor: Some(Side::West),
                    });
                }
            }
        }
        x += w + WALL;
    }

    for room in &rooms {
        canvas.fill(room.rect, true);
        if let Some(side) = room.corridor {
            canvas.fill(corridor_door(&mut rng, &room.rect, side), true);
        }
    }
    let hall = hall.expect("the middle zone has a hall");
    hall_doors(&mut rng, &mut canvas, &hall);

    // Second doors between rooms (and the hall) that share a wall.
    for i in 0..rooms.len() {
        for j in i + 1..rooms.len() {
            if let Some(door) = shared_wall_door(&mut rng, &rooms[i].rect, &rooms[j].rect) {
                if rng.random_bool(P_SECOND_DOOR) {
                    canvas.fill(door, true);
                }
            }
        }
    }

    for room in rooms.iter().filter(|r| r.corridor.is_some()) {
        if rng.random_bool(P_FURNITURE) {
            let n = if room.rect.width() * room.rect.height() > 6000 {
                rng.random_range(1..=2)
            } else {
                1
            };
            let mut placed = Vec::new();
            place_blocks(&mut rng, &room.rect, &mut placed, n, (8, 24), (8, 16), 40);
            for b in placed {
                canvas.fill(b, false);
            }
        }
    }
    furnish_hall(&mut rng, &mut canvas, &hall);
    canvas
}

/// The middle zone's segments, west to east, and the hall's width: two or three
/// blocks and one hall filling `total` cells with walls between them.
fn middle_segments(rng: &mut ChaCha8Rng, total: i64) -> (Vec<Segment>, i64) {
    let block = |rng: &mut ChaCha8Rng| Segment::Block {
        left: rng.random_range(50..=90),
        corridor: rng.random_range(20..=26),
        right: rng.random_range(50..=90),
    };
    for _ in 0..100 {
        let n = rng.random_range(2..=3);
        let mut segs: Vec<Segment> = (0..n).map(|_| block(rng)).collect();
        let used: i64 = segs.iter().map(|s| s.width(0) + WALL).sum();
        let hall = total - used;
        if (HALL.0..=HALL.1).contains(&hall) {
            let at = rng.random_range(0..=segs.len());
            segs.insert(at, Segment::Hall);
            return (segs, hall);
        }
    }
    let b = Segment::Block {
        left: 70,
        corridor: 22,
        right: 70,
    };
    let hall = total - 3 * (b.width(0) + WALL);
    (vec![b, Segment::Hall, b, b], hall)
}

/// A door of random width through the wall on `side` of `room`.
fn corridor_door(rng: &mut ChaCha8Rng, room: &Rect, side: Side) -> Rect {
    let dw = rng.random_range(DOOR.0..=DOOR.1);
    match side {
        Side::North | Side::South => {
            let a = rng.random_range(room.x0 + DOOR_MARGIN..=room.x1 - DOOR_MARGIN - dw);
            let y = if matches!(side, Side::North) {
                room.y1
            } else {
                room.y0 - WALL
            };
            Rect::new(a, y, a + dw, y + WALL)
        }
        Side::East | Side::West => {
            let a = rng.random_range(room.y0 + DOOR_MARGIN..=room.y1 - DOOR_MARGIN - dw);
            let x = if matches!(side, Side::East) {
                room.x1
            } else {
                room.x0 - WALL
            };
            Rect::new(x, a, x + WALL, a + dw)
        }
    }
}

/// A door through the wall between two rooms, if they share a wall long enough.
/// Draws from `rng` only when they do.
fn shared_wall_door(rng: &mut ChaCha8Rng, a: &Rect, b: &Rect) -> Option<Rect> {
    let need = DOOR.1 + 2 * DOOR_MARGIN;
    let (lo, hi) = (a.y0.max(b.y0), a.y1.min(b.y1));
    if (a.x1 + WALL == b.x0 || b.x1 + WALL == a.x0) && hi - lo >= need {
        let x = a.x1.min(b.x1);
        let dw = rng.random_range(DOOR.0..=DOOR.1);
        let y = rng.random_range(lo + DOOR_MARGIN..=hi - DOOR_MARGIN - dw);
        return Some(Rect::new(x, y, x + WALL, y + dw));
    }
    let (lo, hi) = (a.x0.max(b.x0), a.x1.min(b.x1));
    if (a.y1 + WALL == b.y0 || b.y1 + WALL == a.y0) && hi - lo >= need {
        let y = a.y1.min(b.y1);
        let dw = rng.random_range(DOOR.0..=DOOR.1);
        let x = rng.random_range(lo + DOOR_MARGIN..=hi - DOOR_MARGIN - dw);
        return Some(Rect::new(x, y, x + dw, y + WALL));
    }
    None
}

/// Doors from the hall to both long corridors: one per 15 m or so of wall, each in
/// its own stretch of the wall.
fn hall_doors(rng: &mut ChaCha8Rng, canvas: &mut Canvas, hall: &Rect) {
    for y in [hall.y0 - WALL, hall.y1] {
        let n = (hall.width() / 150).clamp(1, 3) + i64::from(rng.random_bool(0.5));
        let slot = hall.width() / n;
        for k in 0..n {
            let dw = DOOR.1;
            let a = hall.x0 + k * slot;
            let x = rng.random_range(a + DOOR_MARGIN..=a + slot - DOOR_MARGIN - dw);
            canvas.fill(Rect::new(x, y, x + dw, y + WALL), true);
        }
    }
}

/// A grid of pillars (0.6 m) every 6–8 m, and desk islands centred between four
/// pillars, all lying the same way, in most of the grid's cells.
fn furnish_hall(rng: &mut ChaCha8Rng, canvas: &mut Canvas, hall: &Rect) {
    let size = 6;
    let spacing = rng.random_range(60..=80);
    let margin = CLEAR + 8;
    let grid = |len: i64| -> Vec<i64> {
        let n = (len - 2 * margin - size) / spacing + 1;
        let off = (len - (n - 1) * spacing - size) / 2;
        (0..n).map(|i| off + i * spacing).collect()
    };
    let (gx, gy) = (grid(hall.width()), grid(hall.height()));
    for &x in &gx {
        for &y in &gy {
            let (px, py) = (hall.x0 + x, hall.y0 + y);
            canvas.fill(Rect::new(px, py, px + size, py + size), false);
        }
    }
    // The room between pillars less the clearance on both sides.
    let room = spacing - size - 2 * CLEAR;
    let along_x = rng.random_bool(0.5);
    for xs in gx.windows(2) {
        for ys in gy.windows(2) {
            if !rng.random_bool(0.7) {
                continue;
            }
            let long = rng.random_range(24..=room);
            let short = rng.random_range(12..=18);
            let (w, h) = if along_x {
                (long, short)
            } else {
                (short, long)
            };
            let cx = hall.x0 + (xs[0] + xs[1] + size) / 2;
            let cy = hall.y0 + (ys[0] + ys[1] + size) / 2;
            canvas.fill(
                Rect::new(cx - w / 2, cy - h / 2, cx - w / 2 + w, cy - h / 2 + h),
                false,
            );
        }
    }
}

/// Add up to `count` solid blocks (sides drawn from `long` and `short`, either
/// orientation) inside `room`, each at least [`CLEAR`] cells from the room's walls and
/// from every block in `placed`; `tries` random positions in all.
fn place_blocks(
    rng: &mut ChaCha8Rng,
    room: &Rect,
    placed: &mut Vec<Rect>,
    count: usize,
    long: (i64, i64),
    short: (i64, i64),
    tries: usize,
) {
    let inner = room.inflate(-CLEAR);
    let mut added = 0;
    for _ in 0..tries {
        if added == count {
            break;
        }
        let (mut w, mut h) = (
            rng.random_range(long.0..=long.1),
            rng.random_range(short.0..=short.1),
        );
        if rng.random_bool(0.5) {
            std::mem::swap(&mut w, &mut h);
        }
        if inner.width() < w || inner.height() < h {
            continue;
        }
        let x = rng.random_range(inner.x0..=inner.x1 - w);
        let y = rng.random_range(inner.y0..=inner.y1 - h);
        let b = Rect::new(x, y, x + w, y + h);
        if placed.iter().all(|p| p.gap(&b) >= CLEAR as f64) {
            placed.push(b);
            added += 1;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::checks::{check_determinism, check_map};
    use super::super::BuiltinMap;

    #[test]
    fn deterministic_and_seed_dependent() {
        check_determinism(BuiltinMap::Office);
    }

    #[test]
    fn ground_truth_properties() {
        for seed in 0..5 {
            check_map(BuiltinMap::Office, seed, (0.88, 0.96));
        }
    }
}
