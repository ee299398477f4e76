//! Every tunable parameter in one serializable struct. Defaults are the paper's
//! (section V: 0.1 m cells, 20 m scanner range, α = 0.01, β = 0.001) where it gives
//! one, and documented choices (docs/DESIGN-CHOICES.md) where it is silent.

mod bounds;
mod targets;

pub use self::targets::{TargetKind, TargetPlacement, TargetSpec, TargetsConfig, MAX_TARGETS};

pub use self::bounds::{
    approx, number, Bound, ConfigError, BOUNDS, MAX_COORDINATE_M, MAX_GRID_SIDE, MAX_WALL_SAMPLES,
};

use serde::{Deserialize, Serialize};

/// How the terms of Eq. (1) are combined.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Scoring {
    /// Each term scaled to [0, 1] over the candidate set, weights read in units of
    /// [`ALPHA_UNIT`] and [`BETA_UNIT`]; the paper's two regimes (α = 0: largest
    /// new area, β = 0: shortest travel) then behave as the paper describes.
    #[default]
    Normalized,
    /// `G = R·(1/P + α/L + β·S)` with clearance and `L` in metres and `S` in cells,
    /// exactly as printed.
    Literal,
}

/// The α of Eq. (1) that gives the travel term the weight 1 in normalized scoring.
pub const ALPHA_UNIT: f64 = 1e-3;
/// The β of Eq. (1) that gives the gain term the weight 1 in normalized scoring.
pub const BETA_UNIT: f64 = 1e-4;

/// The simulated scanner (section V-A).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ScannerConfig {
    /// Maximum range in metres (paper: 20 m).
    pub range: f64,
}

impl Default for ScannerConfig {
    fn default() -> Self {
        Self { range: 20.0 }
    }
}

/// The robots' bodies.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RobotConfig {
    /// Radius of the parent robot in metres: it keeps this clearance from every
    /// known obstacle and every Unknown cell.
    pub radius: f64,
}

impl Default for RobotConfig {
    fn default() -> Self {
        Self { radius: 0.25 }
    }
}

/// The parent planner of section IV-A.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ParentConfig {
    /// Weight α of the travel term `1/L` (Eq. 1).
    pub alpha: f64,
    /// Weight β of the expected-gain term `S` (Eq. 1).
    pub beta: f64,
    /// How the terms are combined.
    pub scoring: Scoring,
    /// Width of the band along the border in which samples are scattered, metres.
    pub band_width: f64,
    /// Samples scattered per square metre of band.
    pub samples_per_m2: f64,
    /// Upper bound on the number of samples.
    pub max_samples: usize,
    /// Band area per k-means cluster, m²: k = ⌈band area / cluster_area⌉.
    pub cluster_area: f64,
    /// Upper bound on k.
    pub max_clusters: usize,
    /// Lloyd iterations of k-means at most.
    pub kmeans_iterations: usize,
    /// A candidate must expect at least this many new cells (`S`) to be chosen.
    pub min_gain_cells: usize,
    /// A candidate must expect at least this much new free area, m², by the
    /// calibrated estimate (beyond the paper; `sensing::GainEstimate`).
    pub min_gain_m2: f64,
    /// A candidate must expect at least this share of the known free area (the
    /// relative stop rule, beyond the paper).
    pub min_gain_share: f64,
    /// The gain estimate counts Unknown cells in view up to this many metres from
    /// known free space.
    pub unknown_depth: f64,
    /// Free area a scan adds per m² of that count, before the episode's own
    /// calibration (docs/RESULTS.md).
    pub gain_scale: f64,
    /// An episode rescales the estimate by Σ actual / Σ estimated gain of its
    /// last this many scans (0: off).
    pub calibration_window: usize,
    /// The calibration never scales the estimate below this factor.
    pub calibration_floor: f64,
    /// Which planner chooses the next scan position.
    pub planner: Planner,
    /// `tour`: the next scan is chosen among this many first stops of the tour
    /// by expected area per scan time and travel (1, the default: the tour's
    /// first stop).
    pub tour_lookahead: usize,
    /// Viewpoints (beyond the paper, after FUEL): for every border group, the
    /// position that sees most of it becomes a candidate beside the band's
    /// centroids (`parent::viewpoints`).
    pub viewpoints: bool,
    /// `tour`: the chosen position hill-climbs on the gain estimate in steps of
    /// this many metres, then half (0: off).
    pub refine_step: f64,
    /// Border fragments (8-connected) smaller than this many cells are ignored.
    pub min_frontier_cells: usize,
    /// Weight γ of the error term (beyond the paper, 0 = off): `G − γ·E`, where `E`
    /// is the predicted growth of the parent's positioning error on the CPS move
    /// to the candidate (normalized scoring: scaled to [0, 1] over the candidates
    /// evaluated; literal: in millimetres). The moves to the best
    /// `error_candidates` candidates by `G` are planned to evaluate it.
    pub gamma: f64,
    /// How many candidates the error term evaluates (their moves are planned).
    pub error_candidates: usize,
    /// `frontier`: explore_lite's `potential_scale`, the weight of the distance.
    pub frontier_potential_scale: f64,
    /// `frontier`: explore_lite's `gain_scale`, the weight of the frontier's size.
    pub frontier_gain_scale: f64,
    /// `frontier`: explore_lite's `min_frontier_size`, metres: smaller frontiers
    /// are ignored.
    pub frontier_min_size: f64,
    /// Sensitivity studies (beyond the paper, 0 = off): the travel term `L` of
    /// Eq. (1) and every leg of the tour multiplied by a fixed pseudo-random
    /// factor in `[1, 1 + travel_jitter]` per cell (per pair of cells) and seed:
    /// the error an approximate `L` with that relative bound may make
    /// (`parent::TravelJitter`; docs/DESIGN-CHOICES.md "Plans against small
    /// errors in L").
    #[serde(skip_serializing_if = "is_zero")]
    pub travel_jitter: f64,
    /// Travel horizon, metres (beyond the paper, after TARE's local planning;
    /// 0 = off): a round weighs only the candidates within this much travel of
    /// the parent (its sweep stops at twice the horizon) and plans the whole
    /// known map only when none of them is worth a scan (`parent::planner`;
    /// docs/DESIGN-CHOICES.md "The travel horizon").
    #[serde(skip_serializing_if = "is_zero")]
    pub horizon: f64,
}

/// Whether a value is exactly zero (an optional key left out of the records).
fn is_zero(v: &f64) -> bool {
    *v == 0.0
}

impl Default for ParentConfig {
    fn default() -> Self {
        Self {
            alpha: 0.01,
            beta: 0.001,
            scoring: Scoring::Normalized,
            band_width: 1.5,
            samples_per_m2: 8.0,
            max_samples: 3000,
            cluster_area: 24.0,
            max_clusters: 24,
            kmeans_iterations: 30,
            min_gain_cells: 10,
            min_gain_m2: 0.1,
            min_gain_share: 0.0005,
            unknown_depth: 2.0,
            gain_scale: 1.0,
            calibration_window: 10,
            calibration_floor: 0.2,
            planner: Planner::Tour,
            tour_lookahead: 1,
            viewpoints: true,
            refine_step: 1.0,
            min_frontier_cells: 2,
            gamma: 0.0,
            error_candidates: 4,
            frontier_potential_scale: 1e-3,
            frontier_gain_scale: 1.0,
            frontier_min_size: 0.5,
            travel_jitter: 0.0,
            horizon: 0.0,
        }
    }
}

/// How long a campaign takes (beyond the paper; defaults in docs/DESIGN-CHOICES.md
/// "Campaign time"): scans, CPS measurements and driving, one robot moving at a
/// time as CPS requires.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct TimeConfig {
    /// One scan, seconds (a full-dome terrestrial scan at survey settings).
    pub scan_s: f64,
    /// One CPS measurement of one child from one station (search, lock, and a
    /// few repeated distance and angle readings), seconds.
    pub measure_s: f64,
    /// Driving speed of every robot, metres per second.
    pub speed_m_s: f64,
}

impl Default for TimeConfig {
    fn default() -> Self {
        Self {
            scan_s: 180.0,
            measure_s: 15.0,
            speed_m_s: 0.5,
        }
    }
}

impl TimeConfig {
    /// The parent travel whose driving takes as long as one scan when the
    /// whole team of `children` children drives it (each robot in turn), metres.
    pub fn scan_equivalent_m(&self, children: usize) -> f64 {
        self.scan_s * self.speed_m_s / (1 + children) as f64
    }
}

/// The parent's planner: where the next scan goes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Planner {
    /// The paper's greedy Eq. (1): the candidate of highest `G`.
    Paper,
    /// The default (chosen by measurement, docs/RESULTS.md): a global tour over
    /// the frontier's candidates (after FUEL, Zhou et al., RA-L 2021): the
    /// shortest open route from the parent through every candidate worth a
    /// scan; the next scan is its first stop.
    #[default]
    Tour,
    /// A baseline: nearest-frontier exploration with the frontier search and cost
    /// of ROS explore_lite (`parent.frontier_*`; see `parent::frontier_goals`).
    Frontier,
    /// A baseline: pure information gain, the candidate of Eq. (1) that would see
    /// the most new cells `S`, however far.
    Gain,
    /// The yardstick (simulation only): the same candidates and reachability,
    /// each scan's gain the true free area it would reveal on the ground truth,
    /// and the candidate of most true gain per metre of travel plus a scan's
    /// worth of driving ([`crate::parent::oracle_rate`]).
    Oracle,
}

impl Planner {
    /// Every planner.
    pub const ALL: [Planner; 5] = [
        Planner::Paper,
        Planner::Tour,
        Planner::Frontier,
        Planner::Gain,
        Planner::Oracle,
    ];

    /// Its name in the configuration and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Planner::Paper => "paper",
            Planner::Tour => "tour",
            Planner::Frontier => "frontier",
            Planner::Gain => "gain",
            Planner::Oracle => "oracle",
        }
    }
}

/// The child robots and the CPS links (sections IV-B and V; Table I).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ChildrenConfig {
    /// Number of children (the paper's simulations used two, the default;
    /// CPS-VIII four). With children every move runs as CPS cycles; 0 lets the
    /// parent move alone.
    pub count: usize,
    /// Radius of each child, metres.
    pub radius: f64,
    /// αc of Eq. (2): weight of the angle term.
    pub alpha_c: f64,
    /// βc of Eq. (2): weight of the distance term.
    pub beta_c: f64,
    /// θt of Eq. (2) in degrees (paper: 90°).
    pub theta_t_deg: f64,
    /// Dt of Eq. (2) in metres (paper: 3 m).
    pub d_t: f64,
    /// Shortest parent–child link, metres (Table I: 1.3 m).
    pub min_range: f64,
    /// Longest parent–child link, metres; `None` means the scanner range.
    pub max_range: Option<f64>,
    /// Clearance above this many metres counts as this much in Eq. (2): a child
    /// farther from every obstacle is no safer, and an uncapped clearance (up to
    /// the scanner range) would drown the angle and distance terms.
    pub clearance_cap: f64,
    /// Least distance, metres, between a parent–child line of sight and every
    /// cell that is not known to be free, cells taken as full squares (a line
    /// touching a wall cell's corner is blocked even at 0). 0 by default: the
    /// wall itself lies somewhere inside its occupied square, so a line clear of
    /// the square already keeps off the wall; more keeps more margin at the cost
    /// of smaller AND regions (docs/DESIGN-CHOICES.md).
    pub sight_clearance: f64,
    /// Radius of each child's marker, metres: the line of sight to one child may
    /// not pass nearer than this to another child's marker (the lines run at
    /// marker height, above the bodies).
    pub marker_radius: f64,
    /// How the children's spots are chosen.
    pub strategy: ChildStrategy,
    /// Strategy `min-error`: the children's travel, metres, counted against the
    /// predicted variance of the parent's next position, mm² per metre.
    pub travel_weight: f64,
}

impl Default for ChildrenConfig {
    fn default() -> Self {
        Self {
            count: 2,
            radius: 0.25,
            alpha_c: 1.0,
            beta_c: 1.0,
            theta_t_deg: 90.0,
            d_t: 3.0,
            min_range: 1.3,
            max_range: None,
            clearance_cap: 1.0,
            sight_clearance: 0.0,
            marker_radius: 0.1,
            strategy: ChildStrategy::MinError,
            travel_weight: 0.01,
        }
    }
}

/// How the children's spots of a cycle are chosen (paper section V-A-2, Fig. 10,
/// and one strategy beyond it).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ChildStrategy {
    /// (a) Random spots in the AND region, valid for CPS.
    Random,
    /// (b) Eq. (2) with the configured weights (αc = βc by default).
    Balanced,
    /// (c) Eq. (2) with αc ≫ βc: the angle term decides (βc / 100).
    Angle,
    /// (d) Eq. (2) with αc ≪ βc: the distance term decides (αc / 100).
    Distance,
    /// (e) The spots, and whether each child stays or moves, that minimise the
    /// predicted covariance of the parent's next pose (the accuracy model), with
    /// `children.travel_weight` trading child travel against it. The default
    /// (chosen by measurement, docs/RESULTS.md).
    #[default]
    MinError,
}

impl ChildStrategy {
    /// Every strategy, in the paper's order.
    pub const ALL: [ChildStrategy; 5] = [
        ChildStrategy::Random,
        ChildStrategy::Balanced,
        ChildStrategy::Angle,
        ChildStrategy::Distance,
        ChildStrategy::MinError,
    ];

    /// The strategy's name in configs and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            ChildStrategy::Random => "random",
            ChildStrategy::Balanced => "balanced",
            ChildStrategy::Angle => "angle",
            ChildStrategy::Distance => "distance",
            ChildStrategy::MinError => "min-error",
        }
    }
}

/// The total station (or scanner) that measures the children's markers: one of the
/// presets of [`crate::accuracy::Instrument`], with any figure overridden.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct InstrumentConfig {
    /// The preset (the paper's TOPCON GPT-9005A by default, Table I).
    pub model: InstrumentModel,
    /// Distance accuracy, constant part, mm (the preset's when absent).
    pub distance_sigma_mm: Option<f64>,
    /// Distance accuracy, part proportional to the distance, ppm.
    pub distance_ppm: Option<f64>,
    /// Angle accuracy (one direction), arc seconds.
    pub angle_sigma_arcsec: Option<f64>,
    /// Shortest measurable distance, m.
    pub min_range: Option<f64>,
    /// Longest measurable distance, m.
    pub max_range: Option<f64>,
    /// Measure slope distances and zenith angles as well (3D positions; markers and
    /// instrument at the heights below over flat ground).
    pub three_d: bool,
    /// Height of the instrument's axis over the ground, m (3D mode).
    pub instrument_height: f64,
    /// Height of the children's markers over the ground, m (3D mode).
    pub marker_height: f64,
}

impl Default for InstrumentConfig {
    fn default() -> Self {
        Self {
            model: InstrumentModel::default(),
            distance_sigma_mm: None,
            distance_ppm: None,
            angle_sigma_arcsec: None,
            min_range: None,
            max_range: None,
            three_d: false,
            instrument_height: 1.0,
            marker_height: 0.5,
        }
    }
}

/// The instrument presets (figures in [`crate::accuracy::Instrument::preset`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum InstrumentModel {
    /// TOPCON GPT-9005A, the paper's (Table I).
    #[default]
    #[serde(rename = "gpt-9005a")]
    Gpt9005a,
    /// Leica Viva TS16, 1″ model.
    #[serde(rename = "ts16")]
    Ts16,
    /// Leica Nova TS60.
    #[serde(rename = "ts60")]
    Ts60,
    /// Topcon MS05AXII.
    #[serde(rename = "ms05axii")]
    Ms05axii,
    /// FARO Focus S 350 laser scanner (markers measured in its own scans, as in
    /// CPS-VIII).
    #[serde(rename = "focus-s350")]
    FocusS350,
}

impl InstrumentModel {
    /// The preset's shortest and longest measurable distance, metres (the
    /// makers' figures; the rest of each preset is in
    /// [`crate::accuracy::Instrument::preset`]).
    pub fn range_m(self) -> (f64, f64) {
        match self {
            InstrumentModel::Gpt9005a => (1.3, 3000.0),
            InstrumentModel::Ts16 | InstrumentModel::Ts60 => (1.5, 3500.0),
            InstrumentModel::Ms05axii => (1.3, 3500.0),
            InstrumentModel::FocusS350 => (0.6, 350.0),
        }
    }

    /// Every preset.
    pub const ALL: [InstrumentModel; 5] = [
        InstrumentModel::Gpt9005a,
        InstrumentModel::Ts16,
        InstrumentModel::Ts60,
        InstrumentModel::Ms05axii,
        InstrumentModel::FocusS350,
    ];

    /// The preset's name in configs and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            InstrumentModel::Gpt9005a => "gpt-9005a",
            InstrumentModel::Ts16 => "ts16",
            InstrumentModel::Ts60 => "ts60",
            InstrumentModel::Ms05axii => "ms05axii",
            InstrumentModel::FocusS350 => "focus-s350",
        }
    }
}

/// The accuracy model's options.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct AccuracyConfig {
    /// Monte Carlo runs through the episode's CPS chain after it ends (0: none).
    pub monte_carlo_runs: usize,
}

/// The registered 3D model each simulated scan contributes to (stage 9,
/// [`crate::model`]): the seen wall cells extruded to a wall height and sampled
/// vertically, every point with the scanner's range noise.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ModelConfig {
    /// Height of the walls over the floor, m.
    pub wall_height: f64,
    /// Vertical spacing of the points on a wall, m.
    pub vertical_step: f64,
    /// Height of the scanner's centre over the floor, m.
    pub scanner_height: f64,
    /// 1σ range noise of every point, mm (the instrument's distance accuracy
    /// `a + b·d` when absent).
    pub range_sigma_mm: Option<f64>,
}

impl Default for ModelConfig {
    fn default() -> Self {
        Self {
            wall_height: 2.0,
            vertical_step: 0.1,
            scanner_height: 1.0,
            range_sigma_mm: None,
        }
    }
}

/// The mission loop.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct MissionConfig {
    /// The mission stops after this many scans.
    pub max_scans: usize,
    /// Diminishing returns (beyond the paper): the mission stops when its last
    /// `stop_window` scans together added less than `stop_share` of the known
    /// free area (0: off).
    pub stop_window: usize,
    /// See `stop_window`.
    pub stop_share: f64,
    /// The tolerance of every scan station (beyond the paper): no station may
    /// scan with a predicted filtering σ above this many metres; the planner
    /// closes the network first (`None`: no tolerance).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_sigma_m: Option<f64>,
}

impl Default for MissionConfig {
    fn default() -> Self {
        Self {
            max_scans: 1000,
            stop_window: 0,
            stop_share: 0.002,
            max_sigma_m: None,
        }
    }
}

/// Limits that keep a run within the machine (docs/USER-GUIDE.md "Limits").
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct LimitsConfig {
    /// Most cells of the planning grid (and pixels of a map image). The default,
    /// 150 million, holds a 1 km × 1 km site at 0.1 m with half again to spare.
    pub max_grid_cells: usize,
    /// Most points of a point cloud read or written. The default, 200 million,
    /// takes about 5 GB as coordinates.
    pub max_cloud_points: usize,
    /// Most memory, MB, a simulated episode may be estimated to need before it
    /// starts ([`crate::mission::MemoryEstimate`]); 0 (the default) means the
    /// memory the machine has available when the run starts, where known.
    pub max_memory_mb: f64,
}

impl Default for LimitsConfig {
    fn default() -> Self {
        Self {
            max_grid_cells: 150_000_000,
            max_cloud_points: 200_000_000,
            max_memory_mb: 0.0,
        }
    }
}

/// A named set of choices a configuration starts from (`preset = "paper"`,
/// `--preset paper`): its keys take the preset's values unless the
/// configuration sets them itself ([`Preset::apply`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Preset {
    /// The paper's choices exactly: the greedy Eq. (1) (`parent.planner =
    /// "paper"`), Eq. (2) with αc = βc (`children.strategy = "balanced"`) and the
    /// paper's stop rule, `S ≥ min_gain_cells` alone (`parent.min_gain_m2 = 0`,
    /// `parent.min_gain_share = 0`, `parent.calibration_window = 0`).
    Paper,
}

impl Preset {
    /// Every preset.
    pub const ALL: [Preset; 1] = [Preset::Paper];

    /// Its name in configurations and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Preset::Paper => "paper",
        }
    }

    /// The configuration keys the preset sets.
    pub fn keys(self) -> &'static [&'static str] {
        match self {
            Preset::Paper => &[
                "parent.planner",
                "children.strategy",
                "parent.min_gain_m2",
                "parent.min_gain_share",
                "parent.calibration_window",
                "parent.viewpoints",
            ],
        }
    }

    /// Gives `config` the preset's value of every key of [`Self::keys`] for which
    /// `set(key)` is false (the configuration did not set it itself), and
    /// records the preset.
    pub fn apply(self, config: &mut Config, set: impl Fn(&str) -> bool) {
        let keep = |key: &str| set(key);
        match self {
            Preset::Paper => {
                if !keep("parent.planner") {
                    config.parent.planner = Planner::Paper;
                }
                if !keep("children.strategy") {
                    config.children.strategy = ChildStrategy::Balanced;
                }
                if !keep("parent.min_gain_m2") {
                    config.parent.min_gain_m2 = 0.0;
                }
                if !keep("parent.min_gain_share") {
                    config.parent.min_gain_share = 0.0;
                }
                if !keep("parent.calibration_window") {
                    config.parent.calibration_window = 0;
                }
                if !keep("parent.viewpoints") {
                    config.parent.viewpoints = false;
                }
            }
        }
        config.preset = Some(self);
    }
}

/// All parameters of a run; printed into every run record.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Config {
    /// Planning grid resolution in metres (paper: 0.1 m); maps are resampled to it.
    pub resolution: f64,
    /// Seed of every random choice.
    pub seed: u64,
    /// Scanner parameters.
    pub scanner: ScannerConfig,
    /// Robot body parameters.
    pub robot: RobotConfig,
    /// Parent planner parameters.
    pub parent: ParentConfig,
    /// Children and CPS links.
    pub children: ChildrenConfig,
    /// Mission loop parameters.
    pub mission: MissionConfig,
    /// The instrument that measures the CPS links.
    pub instrument: InstrumentConfig,
    /// The accuracy model's options.
    pub accuracy: AccuracyConfig,
    /// The registered 3D model.
    pub model: ModelConfig,
    /// The campaign's time model.
    pub time: TimeConfig,
    /// Size limits.
    pub limits: LimitsConfig,
    /// Targets and control points (absent from records when there are none).
    #[serde(skip_serializing_if = "TargetsConfig::is_unset")]
    pub targets: TargetsConfig,
    /// The preset the configuration started from (absent when none; its keys
    /// are already applied, [`Preset::apply`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub preset: Option<Preset>,
}

impl Default for Config {
    fn default() -> Self {
        Self {
            resolution: 0.1,
            seed: 0,
            scanner: ScannerConfig::default(),
            robot: RobotConfig::default(),
            parent: ParentConfig::default(),
            children: ChildrenConfig::default(),
            mission: MissionConfig::default(),
            instrument: InstrumentConfig::default(),
            accuracy: AccuracyConfig::default(),
            model: ModelConfig::default(),
            time: TimeConfig::default(),
            limits: LimitsConfig::default(),
            targets: TargetsConfig::default(),
            preset: None,
        }
    }
}

impl InstrumentConfig {
    /// The instrument's shortest and longest measurable distance, metres: the
    /// preset's, or the configuration's where it gives them.
    pub fn range_m(&self) -> (f64, f64) {
        let (min, max) = self.model.range_m();
        (self.min_range.unwrap_or(min), self.max_range.unwrap_or(max))
    }
}

impl Config {
    /// The configuration of `preset` (the defaults, then the preset's keys).
    pub fn preset(preset: Preset) -> Self {
        let mut c = Self::default();
        preset.apply(&mut c, |_| false);
        c
    }

    /// Scanner range in cells of the planning grid.
    pub fn range_cells(&self) -> f64 {
        self.scanner.range / self.resolution
    }

    /// The shortest and longest parent–child link, metres: `children.min_range`
    /// and `children.max_range` (the scanner's range when absent), within the
    /// instrument's own limits.
    pub fn link_range(&self) -> (f64, f64) {
        let (imin, imax) = self.instrument.range_m();
        let c = &self.children;
        (
            c.min_range.max(imin),
            c.max_range.unwrap_or(self.scanner.range).min(imax),
        )
    }
}

#[cfg(test)]
mod tests;
