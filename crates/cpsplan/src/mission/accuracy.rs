//! The accuracy of a mission's poses: the CPS chain ([`crate::accuracy::Chain`])
//! carried along the executed cycles, its figures written into the records, and
//! the Monte Carlo check of the whole campaign.

use serde::{Deserialize, Serialize};

use super::record::{CycleRecord, MoveRecord};
use super::targets::{TargetOrigin, TargetRecord};
use super::tolerance::Anchor;
use crate::accuracy::{
    monte_carlo, realisation, Chain, CycleGeometry, Instrument, Model, Network, NetworkGeometry,
    PoseCovariance, Role, Script, StationFit, TargetPoint, ARCSEC,
};
use crate::children::target_rule;
use crate::config::{Config, TargetKind};
use crate::geom::{Cell, Point};
use crate::grid::OccupancyGrid;
use crate::sensing::LinkRule;

/// The predicted accuracy of one parent pose (first order, 1σ).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PoseAccuracy {
    /// Radial 1σ of the horizontal position, `sqrt(σx² + σy²)`, metres.
    pub position_sigma_m: f64,
    /// The horizontal position's covariance `[[xx, xy], [xy, yy]]`, m².
    pub covariance_m2: [[f64; 2]; 2],
    /// 1σ of the heading of the instrument's horizontal circle, arc seconds.
    pub heading_sigma_arcsec: f64,
}

impl PoseAccuracy {
    /// A pose known exactly (the first station).
    pub fn exact() -> Self {
        PoseCovariance::default().into()
    }
}

impl From<PoseCovariance> for PoseAccuracy {
    fn from(p: PoseCovariance) -> Self {
        Self {
            position_sigma_m: p.position_sigma(),
            covariance_m2: [[p.xx, p.xy], [p.xy, p.yy]],
            heading_sigma_arcsec: p.heading_sigma() / ARCSEC,
        }
    }
}

/// How the measurements of one scan station are checked and fit in the network
/// adjustment (as survey adjustment software reports them).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FitRecord {
    /// The least redundancy number of the station's measurements: the share of
    /// a blunder in it that the other measurements would reveal (0: none, it is
    /// checked by nothing else; 1: all).
    pub min_redundancy: f64,
    /// The point that least checked measurement went to: `child N` or a
    /// target's name.
    pub least_checked: String,
    /// With a Monte Carlo check: the largest standardized residual `|v| / σ_v`
    /// of the station's readings in the first run, adjusted as a whole.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_standardized_residual: Option<f64>,
    /// The point of that reading.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub worst_fitting: Option<String>,
}

/// The parent's pose at one scan as the CPS estimated it in one noisy
/// realisation of the campaign (the first Monte Carlo run): the pose the scan's
/// points are expressed in ([`crate::model`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PoseEstimate {
    /// The estimated scan position, world frame.
    pub position: Point,
    /// Radial error of that position, metres.
    pub position_error_m: f64,
    /// Error of the estimated height, metres (0 in 2D).
    pub height_error_m: f64,
    /// Error of the estimated heading, arc seconds.
    pub heading_error_arcsec: f64,
}

impl PoseEstimate {
    /// The estimate of a pose truly at `truth` with error `[x, y, z, ω]` (metres,
    /// radians).
    pub fn new(truth: Point, error: [f64; 4]) -> Self {
        Self {
            position: Point::new(truth.x + error[0], truth.y + error[1]),
            position_error_m: error[0].hypot(error[1]),
            height_error_m: error[2],
            heading_error_arcsec: error[3] / ARCSEC,
        }
    }

    /// The heading error, radians.
    pub fn heading_error_rad(&self) -> f64 {
        self.heading_error_arcsec * ARCSEC
    }
}

/// The CPS chain of a mission and its network: the filtering chain the planners
/// ask, the geometry of every cycle run so far (for the Monte Carlo check), the
/// whole network adjusted as it grows (for the smoothed figures), and the
/// targets with their records. No chain when the team cannot fix the parent's
/// pose (fewer than two children).
#[derive(Debug, Clone)]
pub struct Tracker {
    chain: Option<Chain>,
    geometry: NetworkGeometry,
    network: Option<Network>,
    /// Index of the last cycle of each executed move, in order.
    move_ends: Vec<usize>,
    rule: LinkRule,
    targets: Vec<TargetRecord>,
    closures: usize,
    /// The filtering σ of the last station that measured a target.
    anchor: f64,
    /// Stations that measured a target or control point.
    anchors: Vec<Anchor>,
}

impl Tracker {
    /// The chain of a team of `config.children.count` children, the parent's
    /// pose at `start` known exactly, with the configuration's targets and
    /// control points.
    pub fn new(config: &Config, start: Point) -> Self {
        let model = Model::new(Instrument::from_config(&config.instrument));
        let n = config.children.count;
        let given: Vec<TargetPoint> = config
            .targets
            .points
            .iter()
            .map(|p| TargetPoint {
                position: Point::new(p.x, p.y),
                z: p.z,
                control_sigma: match p.kind {
                    TargetKind::Control => p.sigma_mm.map(|s| s * 1e-3),
                    TargetKind::Free => None,
                },
            })
            .collect();
        let chain = (n >= 2).then(|| {
            let mut c = Chain::new(model, start, n);
            for &t in &given {
                c.add_target(t);
            }
            c
        });
        let network = chain
            .is_some()
            .then(|| Network::new(Script::new(model, start, n, &given)));
        let targets = config
            .targets
            .points
            .iter()
            .enumerate()
            .map(|(i, p)| TargetRecord {
                name: config.targets.name_of(i),
                origin: match p.kind {
                    TargetKind::Control => TargetOrigin::Control,
                    TargetKind::Free => TargetOrigin::Free,
                },
                position: Point::new(p.x, p.y),
                sigma_mm: p.sigma_mm.filter(|_| p.kind == TargetKind::Control),
                placed_at_scan: None,
                placed_by_child: None,
                reason: None,
                first_measured_scan: None,
                measurements: 0,
                smoothed_sigma_m: None,
            })
            .collect();
        Self {
            chain,
            geometry: NetworkGeometry {
                start,
                targets: given,
                ..NetworkGeometry::default()
            },
            network,
            move_ends: Vec::new(),
            rule: target_rule(config),
            targets,
            closures: 0,
            anchor: 0.0,
            anchors: Vec::new(),
        }
    }

    /// Earlier stations that measured a target or control point: where a
    /// closure can return to.
    pub fn anchors(&self) -> &[Anchor] {
        &self.anchors
    }

    /// Notes the station at `position` with filtering σ `sigma` that measured
    /// `sighted`, as an anchor when it measured enough.
    fn note_anchor(&mut self, position: Point, sigma: f64, sighted: &[usize]) {
        let control = sighted.iter().any(|&t| {
            self.targets
                .get(t)
                .is_some_and(|r| r.origin == TargetOrigin::Control)
        });
        if sighted.is_empty() && !control {
            return;
        }
        if let Some(a) = self
            .anchors
            .iter_mut()
            .find(|a| a.position.distance(position) < 1.0)
        {
            if sigma < a.sigma_m {
                *a = Anchor {
                    position,
                    sigma_m: sigma,
                    targets: sighted.len(),
                };
            }
            return;
        }
        self.anchors.push(Anchor {
            position,
            sigma_m: sigma,
            targets: sighted.len(),
        });
    }

    /// The filtering σ of the last station that measured a target or control
    /// point (0 before any), metres.
    pub fn anchor_sigma(&self) -> f64 {
        self.anchor
    }

    /// Targets the team has left so far.
    pub fn placed(&self) -> usize {
        self.targets
            .iter()
            .filter(|t| t.origin == TargetOrigin::Placed)
            .count()
    }

    /// The CPS chain where the team stands now.
    pub fn chain(&self) -> Option<&Chain> {
        self.chain.as_ref()
    }

    /// The predicted accuracy of the parent's current pose.
    pub fn current(&self) -> Option<PoseAccuracy> {
        self.chain.as_ref().map(|c| c.pose().into())
    }

    /// The targets and control points so far, given and placed.
    pub fn targets(&self) -> &[TargetRecord] {
        &self.targets
    }

    /// The stations so far that measured a control point, or a target first
    /// measured at least two scans before: the network's closures.
    pub fn closures(&self) -> usize {
        self.closures
    }

    /// The rule by which stations measure targets.
    pub fn rule(&self) -> &LinkRule {
        &self.rule
    }

    /// The first station (scan 1 at `at`) measures the targets in sight on
    /// `knowledge`; returns them.
    pub fn sight_start(&mut self, knowledge: &OccupancyGrid, at: Cell) -> Vec<usize> {
        let Some(chain) = self.chain.as_mut() else {
            return Vec::new();
        };
        let sighted = chain.in_sight(knowledge, at, &self.rule);
        if sighted.is_empty() {
            return sighted;
        }
        if chain.sight_here(&sighted).is_err() {
            self.chain = None;
            return Vec::new();
        }
        self.geometry.at_start = sighted.clone();
        let start = self.geometry.start;
        self.note_anchor(start, 0.0, &sighted);
        if let Some(n) = self.network.as_mut() {
            n.script_mut().sight_here(&sighted);
            if n.extend_nominal().is_err() {
                self.network = None;
            }
        }
        self.note_measured(&sighted, 1);
        sighted
    }

    fn note_measured(&mut self, sighted: &[usize], scan: usize) -> bool {
        let mut closes = false;
        for &t in sighted {
            let Some(r) = self.targets.get_mut(t) else {
                continue;
            };
            r.measurements += 1;
            match r.first_measured_scan {
                None => r.first_measured_scan = Some(scan),
                Some(first) if first + 2 <= scan => closes = true,
                Some(_) => {}
            }
            if r.origin == TargetOrigin::Control {
                closes = true;
            }
        }
        closes
    }

    /// Registers the targets the move's children leave (`left_targets` of its
    /// cycles, indices assigned here), writes into `movement` the targets each
    /// station measures and the predicted σ after each cycle, and carries the
    /// chain and the network along it when `execute` (a move planned at the scan
    /// limit is only recorded). `scan` is the scan the move starts from. A
    /// geometry the chain cannot handle ends the prediction.
    pub fn follow(
        &mut self,
        knowledge: &OccupancyGrid,
        movement: &mut MoveRecord,
        execute: bool,
        scan: usize,
    ) {
        let Some(chain) = self.chain.as_ref() else {
            return;
        };
        let before = chain.pose().position_sigma();
        let mut next = chain.clone();
        let mut records = self.targets.clone();
        let mut ok = true;
        let mut geometry = Vec::with_capacity(movement.cycles.len());
        let g = knowledge.geometry();
        for cycle in &mut movement.cycles {
            let mut here = Vec::new();
            for left in &mut cycle.left_targets {
                left.target = next.add_target(TargetPoint::free(left.position));
                let ordinal = records
                    .iter()
                    .filter(|r| r.origin == TargetOrigin::Placed)
                    .count()
                    + 1;
                records.push(TargetRecord::placed(left, ordinal, scan));
                here.push(left.target);
            }
            if next.sight_here(&here).is_err() {
                ok = false;
                break;
            }
            let mut c = geometry_of(cycle);
            c.here = here;
            if let Some(to) = g.world_to_cell(cycle.parent_to) {
                c.sighted = next.in_sight(knowledge, to, &self.rule);
            }
            match next.cycle_sighting(c.to, &c.children, &c.moved, &c.sighted) {
                Ok(p) => cycle.position_sigma_m = Some(p.position_sigma()),
                Err(_) => {
                    ok = false;
                    break;
                }
            }
            cycle.targets = c.sighted.clone();
            geometry.push(c);
        }
        if !execute {
            return;
        }
        if !ok {
            self.chain = None;
            self.network = None;
            return;
        }
        self.targets = records;
        for (c, cycle) in geometry.iter().zip(&movement.cycles) {
            let placed = c.here.clone();
            if !placed.is_empty() {
                self.anchor = before;
            }
            self.note_measured(&placed, scan);
            if self.note_measured(&c.sighted, scan + 1) {
                self.closures += 1;
            }
            if !c.sighted.is_empty() {
                self.anchor = cycle.position_sigma_m.unwrap_or(self.anchor);
                if let Some(sigma) = cycle.position_sigma_m {
                    self.note_anchor(c.to, sigma, &c.sighted);
                }
            }
        }
        if let Some(n) = self.network.as_mut() {
            for c in &geometry {
                for &t in &c.here {
                    while n.script().target_count() <= t {
                        let p = self.targets[n.script().target_count()].position;
                        n.script_mut().add_target(TargetPoint::free(p));
                    }
                }
                n.script_mut().cycle(c);
            }
            if n.extend_nominal().is_err() {
                self.network = None;
            }
        }
        if !geometry.is_empty() {
            for c in &geometry {
                for &t in &c.here {
                    while self.geometry.targets.len() <= t {
                        let p = self.targets[self.geometry.targets.len()].position;
                        self.geometry.targets.push(TargetPoint::free(p));
                    }
                }
            }
            self.geometry.cycles.extend(geometry);
            self.move_ends.push(self.geometry.cycles.len() - 1);
        }
        self.chain = Some(next);
    }

    /// The name of the point a measurement went to.
    fn point_name(&self, role: Role) -> String {
        match role {
            Role::Child(i) => format!("child {}", i + 1),
            Role::Target(t) => self
                .targets
                .get(t)
                .map_or_else(|| format!("target {}", t + 1), |r| r.name.clone()),
            Role::Station(k) => format!("station {k}"),
        }
    }

    /// How every scan station's measurements are checked (redundancy numbers of
    /// the nominal network), scan by scan; the first station's too.
    pub fn checks(&self) -> Option<Vec<Option<FitRecord>>> {
        let net = self.network.as_ref()?;
        let fits = net.station_fits().ok()?;
        let scans = std::iter::once(0).chain(self.move_ends.iter().map(|&c| c + 1));
        Some(
            scans
                .map(|k| {
                    fits.get(k).copied().flatten().map(|f| FitRecord {
                        min_redundancy: f.min_redundancy.0,
                        least_checked: self.point_name(f.min_redundancy.1),
                        max_standardized_residual: None,
                        worst_fitting: None,
                    })
                })
                .collect(),
        )
    }

    /// The worst-fitting reading of every scan station in a realisation's
    /// adjustment, scan by scan (standardized residual and point).
    fn worst_readings(&self, fits: &[Option<StationFit>]) -> Vec<Option<(f64, String)>> {
        std::iter::once(0)
            .chain(self.move_ends.iter().map(|&c| c + 1))
            .map(|k| {
                fits.get(k)
                    .copied()
                    .flatten()
                    .map(|f| (f.max_standardized.0, self.point_name(f.max_standardized.1)))
            })
            .collect()
    }

    /// The smoothed accuracy of every scan after the first (one per executed
    /// move), every measurement of the episode at once; records each target's
    /// smoothed σ. `None` without a network or when it cannot be solved.
    pub fn smooth(&mut self) -> Option<Vec<PoseAccuracy>> {
        let net = self.network.as_ref()?;
        let cov = net.smooth().ok()?;
        let model = net.model();
        let script = net.script();
        for (t, r) in self.targets.iter_mut().enumerate() {
            r.smoothed_sigma_m = script
                .target_var(t)
                .and_then(|v| cov[v].as_ref())
                .map(|c| (c[(0, 0)] + c[(1, 1)]).max(0.0).sqrt());
        }
        let stations = script.stations();
        self.move_ends
            .iter()
            .map(|&c| {
                let m = cov.get(*stations.get(c + 1)?)?.as_ref()?;
                Some(PoseCovariance::from_matrix(&model, m).into())
            })
            .collect()
    }

    /// The first Monte Carlo run seeded by `seed`: the pose errors `[x, y, z,
    /// ω]` at every scan after the first (one per executed move), filtering and
    /// smoothed, and every scan station's worst-fitting reading; `None` without
    /// a chain.
    pub fn realisation(&self, seed: u64) -> Option<ScanRealisation> {
        let chain = self.chain.as_ref()?;
        let r = realisation(chain.model(), &self.geometry, seed, 0, true).ok()?;
        let pick =
            |e: &[[f64; 4]]| -> Vec<[f64; 4]> { self.move_ends.iter().map(|&c| e[c]).collect() };
        Some(ScanRealisation {
            filtering: pick(&r.filtering),
            smoothed: r.smoothed.as_deref().map(pick),
            worst: r
                .fits
                .as_deref()
                .map(|f| self.worst_readings(f))
                .unwrap_or_default(),
        })
    }

    /// The Monte Carlo mean radial error at every scan after the first (one per
    /// executed move), filtering and smoothed, with `runs` runs seeded by `seed`;
    /// `None` without a chain.
    pub fn monte_carlo(&self, runs: usize, seed: u64) -> Option<(Vec<f64>, Option<Vec<f64>>)> {
        let chain = self.chain.as_ref()?;
        if runs == 0 {
            return None;
        }
        let mc = monte_carlo(chain.model(), &self.geometry, runs, seed, true).ok()?;
        let pick = |e: &[f64]| -> Vec<f64> { self.move_ends.iter().map(|&c| e[c]).collect() };
        Some((
            pick(&mc.mean_error),
            mc.smoothed_mean_error.as_deref().map(pick),
        ))
    }
}

/// The first Monte Carlo run of a mission, scan by scan ([`Tracker::realisation`]).
#[derive(Debug, Clone, PartialEq)]
pub struct ScanRealisation {
    /// Filtering errors `[x, y, z, ω]` of every scan after the first.
    pub filtering: Vec<[f64; 4]>,
    /// Smoothed errors of every scan after the first.
    pub smoothed: Option<Vec<[f64; 4]>>,
    /// Every scan station's worst-fitting reading (standardized residual and
    /// point), the first included.
    pub worst: Vec<Option<(f64, String)>>,
}

/// The chain's view of a recorded cycle (without targets).
fn geometry_of(cycle: &CycleRecord) -> CycleGeometry {
    CycleGeometry::plain(
        cycle.parent_to,
        cycle.children.iter().map(|c| c.to).collect(),
        cycle.children.iter().map(|c| !c.stays).collect(),
    )
}
