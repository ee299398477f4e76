//! The geometry of a CPS network as the parent measured it: the first station,
//! the targets and control points, and per cycle where the parent went, where
//! every child stood, and which targets each station measured. The chain
//! ([`super::Chain`]), the batch adjustment ([`super::batch_covariances`]), the
//! network adjustment ([`super::Network`]) and the Monte Carlo check all read a
//! campaign in this form.

use crate::geom::Point;

/// A fixed target or control point of a network.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct TargetPoint {
    /// Where it stands, world frame.
    pub position: Point,
    /// Its height over the floor in 3D mode (`None`: the markers' height).
    pub z: Option<f64>,
    /// A control point's standard deviation of each coordinate, metres (`None`:
    /// a free target, unknown until a station measures it).
    pub control_sigma: Option<f64>,
}

impl TargetPoint {
    /// A free target at `position`.
    pub fn free(position: Point) -> Self {
        Self {
            position,
            ..Self::default()
        }
    }

    /// A control point at `position` known to `sigma` metres per coordinate.
    pub fn control(position: Point, sigma: f64) -> Self {
        Self {
            position,
            control_sigma: Some(sigma),
            ..Self::default()
        }
    }
}

/// One cycle of a network: the targets measured from the station where it
/// begins (targets left there), where the parent goes, where every child stands,
/// which children moved to stand there, and which targets the new station
/// measures.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct CycleGeometry {
    /// The parent's position after the cycle.
    pub to: Point,
    /// Every child's point during the cycle.
    pub children: Vec<Point>,
    /// Whether each child moved (got a new point) in this cycle.
    pub moved: Vec<bool>,
    /// Targets (indices into the network's targets) first measured from the
    /// station where the cycle begins: targets the children left there.
    pub here: Vec<usize>,
    /// Targets the new station measures.
    pub sighted: Vec<usize>,
}

impl CycleGeometry {
    /// A cycle without targets.
    pub fn plain(to: Point, children: Vec<Point>, moved: Vec<bool>) -> Self {
        Self {
            to,
            children,
            moved,
            ..Self::default()
        }
    }
}

/// A whole network: the first station (known exactly), its targets, and its
/// cycles.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct NetworkGeometry {
    /// The parent's first station, known exactly (the datum).
    pub start: Point,
    /// Every target and control point, given or left by the team.
    pub targets: Vec<TargetPoint>,
    /// Targets measured from the first station.
    pub at_start: Vec<usize>,
    /// The cycles in order.
    pub cycles: Vec<CycleGeometry>,
}

impl NetworkGeometry {
    /// A chain without targets.
    pub fn chain(start: Point, cycles: Vec<CycleGeometry>) -> Self {
        Self {
            start,
            cycles,
            ..Self::default()
        }
    }

    /// Number of children (0 without cycles).
    pub fn children(&self) -> usize {
        self.cycles.first().map_or(0, |c| c.children.len())
    }
}
