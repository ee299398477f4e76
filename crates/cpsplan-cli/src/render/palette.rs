//! The colours of every picture.

use super::canvas::Rgb;

/// Known free space.
pub const FREE: Rgb = Rgb::hex(0xffffff);
/// Known obstacles.
pub const OCCUPIED: Rgb = Rgb::hex(0x2b2b2b);
/// Never observed, not part of the reachable space.
pub const UNKNOWN: Rgb = Rgb::hex(0xd5dae1);
/// Reachable free space that was never observed.
pub const MISSED: Rgb = Rgb::hex(0xf6c9a0);
/// Walls bordering the reachable space that were never observed.
pub const MISSED_WALL: Rgb = Rgb::hex(0xd08a4e);
/// Free space connected to the start but out of the robot's reach (behind
/// gaps narrower than the robot), never observed.
pub const OUT_OF_REACH: Rgb = Rgb::hex(0xd8c6ea);
/// The parent's path.
pub const TRAJECTORY: Rgb = Rgb::hex(0x1f77b4);
/// The children's paths, child 1 first (repeats for more children).
pub const CHILDREN: [Rgb; 4] = [
    Rgb::hex(0x9467bd),
    Rgb::hex(0x17becf),
    Rgb::hex(0x8c564b),
    Rgb::hex(0xe377c2),
];
/// Scan positions.
pub const SCAN: Rgb = Rgb::hex(0xff7f0e);
/// The first scan (the start).
pub const START: Rgb = Rgb::hex(0x2ca02c);
/// The last scan.
pub const END: Rgb = Rgb::hex(0xd62728);
/// Body text.
pub const TEXT: Rgb = Rgb::hex(0x1a1a1a);
/// Secondary text.
pub const MUTED_TEXT: Rgb = Rgb::hex(0x4a5360);
/// Thin separators and the map frame.
pub const RULE: Rgb = Rgb::hex(0xc4cad2);
/// Outline of legend swatches and label boxes.
pub const SWATCH_EDGE: Rgb = Rgb::hex(0x8a939e);
/// Subgoals retrieved on the Visibility Graph, and the graph path through them.
pub const SUBGOAL: Rgb = Rgb::hex(0x0b2e59);
/// AND regions (section IV-B), blended over the map.
pub const AND_REGION: Rgb = Rgb::hex(0x2ca02c);
/// Targets the CPS move gave up.
pub const REJECTED: Rgb = Rgb::hex(0xd62728);
/// Candidates that may not be chosen.
pub const INELIGIBLE: Rgb = Rgb::hex(0x9aa3ad);
/// The ramp of candidate scores `G`, low to high.
pub const SCORE_RAMP: [Rgb; 5] = [
    Rgb::hex(0xfee391),
    Rgb::hex(0xfdb14f),
    Rgb::hex(0xf2712b),
    Rgb::hex(0xcf3a1c),
    Rgb::hex(0x8c1a0f),
];
/// Error ellipses of the scan positions.
pub const ELLIPSE: Rgb = Rgb::hex(0x6a3d9a);
/// Targets (fixed points the team or the site set up).
pub const TARGET: Rgb = Rgb::hex(0x00796b);
/// Control points (known coordinates).
pub const CONTROL: Rgb = Rgb::hex(0x1b5e20);
/// Lines along which stations measured targets.
pub const SIGHT: Rgb = Rgb::hex(0x26a69a);
/// The smoothed error curve.
pub const SMOOTHED: Rgb = Rgb::hex(0x1b9e77);
