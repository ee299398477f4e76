//! A real team's network: the stations and points its readings name, adjusted
//! as a whole, with every reading checked (beyond the paper; docs/USER-GUIDE.md
//! "Campaigns").
//!
//! In: the datum (the first station's name, place and the direction of its
//! instrument's zero), the control points' known coordinates, every [`Reading`]
//! in the order it was taken. Out: every station's and point's adjusted
//! coordinates and covariance ([`Survey`]), and the readings left out as
//! blunders.
//!
//! Unknowns appear in the order the readings name them: a station when its
//! first reading comes, a point when it is first measured. Child markers are
//! named `C<child>.<spot>`: a child's new spot replaces its old one, which is
//! never measured again. Every other point (a target, a control point) stays
//! measurable for the whole campaign.
//!
//! *Approximate coordinates*, as survey software computes them before an
//! adjustment: a new station from its readings to at least two points known
//! before it (a 2D similarity fit of their directions and horizontal
//! distances: a resection), a new point by the polar reading from its station.
//!
//! *Blunder detection* (data snooping): after the adjustment the largest
//! standardized residual among the readings under check is compared with
//! [`BLUNDER_SIGMAS`]; above it, that reading is left out, named, and the
//! network adjusted again, until every reading under check fits.

use std::collections::HashMap;

use nalgebra::{DMatrix, DVector};
use thiserror::Error;

use super::model::Model;
use super::network::{Network, NetworkError};
use super::reading::Reading;
use super::script::{Role, Script};
use crate::geom::Point;

/// The standardized residual above which a reading is a blunder: 4 (a good
/// reading exceeds it once in about 16 000; Baarda's 3.29 is the 0.1 % level
/// of a single test, and a campaign tests thousands).
pub const BLUNDER_SIGMAS: f64 = 4.0;

/// Gauss–Newton passes of one adjustment.
const ITERATIONS: usize = 20;

/// The first station of a network: known exactly.
#[derive(Debug, Clone, PartialEq)]
pub struct Datum {
    /// Its name in the readings.
    pub station: String,
    /// Where it stands, world frame.
    pub position: Point,
    /// Where its instrument's zero points: counter-clockwise from the world's
    /// x axis, radians.
    pub heading_rad: f64,
}

/// A point of known coordinates.
#[derive(Debug, Clone, PartialEq)]
pub struct ControlPoint {
    /// Its name in the readings.
    pub name: String,
    /// Its coordinates, world frame.
    pub position: Point,
    /// Its height (3D model; the marker height when `None`).
    pub z: Option<f64>,
    /// 1σ of its coordinates, metres.
    pub sigma_m: f64,
}

/// A station or point after the adjustment.
#[derive(Debug, Clone, PartialEq)]
pub struct Adjusted {
    /// Its name.
    pub name: String,
    /// The adjusted unknown: a station `[x, y, ω]` (3D `[x, y, z, ω]`), a
    /// point `[x, y]` (3D `[x, y, z]`).
    pub value: DVector<f64>,
    /// Its covariance given every reading (zero for the datum).
    pub covariance: DMatrix<f64>,
}

impl Adjusted {
    /// The horizontal position.
    pub fn position(&self) -> Point {
        Point::new(self.value[0], self.value[1])
    }

    /// The horizontal position's covariance `[[xx, xy], [xy, yy]]`.
    pub fn covariance_2d(&self) -> [[f64; 2]; 2] {
        let c = &self.covariance;
        [[c[(0, 0)], c[(0, 1)]], [c[(1, 0)], c[(1, 1)]]]
    }

    /// The radial 1σ `sqrt(σx² + σy²)`, metres.
    pub fn sigma_m(&self) -> f64 {
        (self.covariance[(0, 0)] + self.covariance[(1, 1)]).sqrt()
    }
}

/// A reading left out of the adjustment.
#[derive(Debug, Clone, PartialEq)]
pub struct Blunder {
    /// Its index among the readings given.
    pub reading: usize,
    /// Its standardized residual when it was found (the largest of its
    /// components).
    pub standardized: f64,
}

/// The adjusted network.
#[derive(Debug, Clone, PartialEq)]
pub struct Survey {
    /// Every station in the order it was set up (the datum first).
    pub stations: Vec<Adjusted>,
    /// Every point in the order it was first measured.
    pub points: Vec<Adjusted>,
    /// The readings left out, in the order they were found.
    pub left_out: Vec<Blunder>,
    /// The largest standardized residual of the readings kept under check.
    pub max_standardized: f64,
}

impl Survey {
    /// The station or point named `name`.
    pub fn get(&self, name: &str) -> Option<&Adjusted> {
        self.stations
            .iter()
            .chain(&self.points)
            .find(|a| a.name == name)
    }
}

/// Why readings cannot be adjusted.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum SurveyError {
    /// A new station measured fewer than two points known before it.
    #[error(
        "station {station} measured {known} point{} known before it; a station needs readings to at least 2 (a child's marker, a target or a control point measured before)",
        if *known == 1 { "" } else { "s" }
    )]
    TooFewKnown {
        /// The station.
        station: String,
        /// The known points it measured.
        known: usize,
    },
    /// A child's old spot was measured after its new one replaced it.
    #[error(
        "{point} is measured after {newer} replaced it: a child's spots are measured in order"
    )]
    Replaced {
        /// The old spot.
        point: String,
        /// The spot that replaced it.
        newer: String,
    },
    /// A station measured itself, or a station's name names a point.
    #[error("{0} is both a station and a point")]
    StationIsPoint(String),
    /// The readings do not fix the network.
    #[error("the readings do not fix {name}: too few of them, or all in one line")]
    Underdetermined {
        /// The unknown.
        name: String,
    },
    /// The network cannot be solved.
    #[error("the readings do not fix the network together")]
    Singular,
    /// Readings disagree, and the suspect alone fixes an unknown.
    #[error(
        "{reading} does not fit ({standardized:.1}σ), and without it the readings do not fix {name}: measure again"
    )]
    BlunderNeeded {
        /// The reading, as `station → point`.
        reading: String,
        /// Its standardized residual.
        standardized: f64,
        /// The unknown it alone fixes.
        name: String,
    },
    /// Readings disagree, and any one of several could be the blunder: they
    /// check only each other.
    #[error(
        "the readings disagree (up to {standardized:.1}σ): one of {} is off, and they check only each other; measure again",
        readings.join(", ")
    )]
    Ambiguous {
        /// The suspects, as `station → point`.
        readings: Vec<String>,
        /// The largest standardized residual.
        standardized: f64,
    },
}

/// The child and spot of a child marker's name `C<child>.<spot>` (children
/// from 1).
pub fn child_spot(name: &str) -> Option<(usize, usize)> {
    let rest = name.strip_prefix('C')?;
    let (child, spot) = rest.split_once('.')?;
    let all_digits = |s: &str| !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit());
    if !all_digits(child) || !all_digits(spot) {
        return None;
    }
    let child: usize = child.parse().ok()?;
    Some((child.checked_sub(1)?, spot.parse().ok()?))
}

/// Adjusts `readings` (in the order they were taken) on `datum` and
/// `controls`; the readings from `check_from` on are checked for blunders
/// (those before were checked when they came).
pub fn adjust_readings(
    model: Model,
    datum: &Datum,
    controls: &[ControlPoint],
    readings: &[Reading],
    check_from: usize,
) -> Result<Survey, SurveyError> {
    let mut left_out: Vec<Blunder> = Vec::new();
    loop {
        let trial = Trial::run(model, datum, controls, readings, &left_out, check_from)?;
        let Some(&(_, w)) = trial.suspects.first() else {
            return trial.built.survey(&trial.network, left_out, trial.max);
        };
        if w <= BLUNDER_SIGMAS {
            return trial.built.survey(&trial.network, left_out, trial.max);
        }
        // The suspects nearly as bad as the worst: which of them, left out,
        // lets the others fit?
        let near: Vec<(usize, f64)> = trial
            .suspects
            .iter()
            .copied()
            .take_while(|&(_, v)| v >= NEAR_TIE * w)
            .collect();
        let mut explains = Vec::new();
        let mut determined = Vec::new();
        let mut unfixed: Option<String> = None;
        for &(r, v) in &near {
            let mut without = left_out.clone();
            without.push(Blunder {
                reading: r,
                standardized: v,
            });
            match Trial::run(model, datum, controls, readings, &without, check_from) {
                Ok(t) => {
                    determined.push((r, v));
                    if t.max <= BLUNDER_SIGMAS {
                        explains.push((r, v));
                    }
                }
                Err(
                    SurveyError::Underdetermined { name }
                    | SurveyError::TooFewKnown { station: name, .. },
                ) => {
                    unfixed.get_or_insert(name);
                }
                Err(e) => return Err(e),
            }
        }
        let (r, v) = match (explains.as_slice(), determined.first()) {
            ([one], _) => *one,
            ([], Some(&first)) => first,
            ([], None) => {
                let over: Vec<(usize, f64)> = trial
                    .suspects
                    .iter()
                    .copied()
                    .take_while(|&(_, v)| v > BLUNDER_SIGMAS)
                    .take(MAX_NAMED)
                    .collect();
                if let [(r, v)] = over.as_slice() {
                    return Err(SurveyError::BlunderNeeded {
                        reading: reading_name(&readings[*r]),
                        standardized: *v,
                        name: unfixed.unwrap_or_else(|| readings[*r].point.clone()),
                    });
                }
                return Err(SurveyError::Ambiguous {
                    readings: over
                        .iter()
                        .map(|&(r, _)| reading_name(&readings[r]))
                        .collect(),
                    standardized: w,
                });
            }
            (many, _) => {
                return Err(SurveyError::Ambiguous {
                    readings: many
                        .iter()
                        .map(|&(r, _)| reading_name(&readings[r]))
                        .collect(),
                    standardized: w,
                })
            }
        };
        left_out.push(Blunder {
            reading: r,
            standardized: v,
        });
    }
}

/// Suspects whose standardized residual is at least this share of the worst's
/// are tried as the blunder too (in a loop with one redundant reading every
/// reading has the same standardized residual).
const NEAR_TIE: f64 = 0.9;

/// The most suspects an error names.
const MAX_NAMED: usize = 6;

/// One adjustment of the readings not left out.
struct Trial {
    built: Built,
    network: Network,
    /// The readings under check by decreasing standardized residual.
    suspects: Vec<(usize, f64)>,
    /// The largest standardized residual under check.
    max: f64,
}

impl Trial {
    fn run(
        model: Model,
        datum: &Datum,
        controls: &[ControlPoint],
        readings: &[Reading],
        left_out: &[Blunder],
        check_from: usize,
    ) -> Result<Self, SurveyError> {
        let kept: Vec<usize> = (0..readings.len())
            .filter(|i| !left_out.iter().any(|b| b.reading == *i))
            .collect();
        let built = Built::new(model, datum, controls, readings, &kept)?;
        let mut network = Network::new(built.script.clone());
        let values = built.values(readings);
        let fits = network
            .extend(values, |_, v| v.truth.clone(), |_, v| v.truth.clone())
            .and_then(|()| network.adjust(ITERATIONS))
            .and_then(|_| network.fits())
            .map_err(|e| built.error(e))?;
        let mut suspects: Vec<(usize, f64)> = fits
            .iter()
            .map(|f| (built.order[f.measurement], f.standardized))
            .filter(|&(r, _)| r >= check_from)
            .collect();
        suspects.sort_by(|a, b| b.1.total_cmp(&a.1));
        let max = suspects.first().map_or(0.0, |s| s.1);
        Ok(Self {
            built,
            network,
            suspects,
            max,
        })
    }
}

/// `station → point` of reading `r`.
pub fn reading_name(r: &Reading) -> String {
    format!("{} \u{2192} {}", r.station, r.point)
}

/// The script of the kept readings, with every unknown's approximate
/// coordinates and name.
struct Built {
    script: Script,
    names: Vec<String>,
    /// The reading of every measurement of the script, in order.
    order: Vec<usize>,
}

impl Built {
    fn new(
        model: Model,
        datum: &Datum,
        controls: &[ControlPoint],
        readings: &[Reading],
        kept: &[usize],
    ) -> Result<Self, SurveyError> {
        let children = kept
            .iter()
            .filter_map(|&i| child_spot(&readings[i].point))
            .map(|(c, _)| c + 1)
            .max()
            .unwrap_or(0);
        let mut script = Script::with_datum(
            model,
            model.station(datum.position, datum.heading_rad),
            children,
        );
        let mut var: HashMap<&str, usize> = HashMap::from([(datum.station.as_str(), 0)]);
        let mut current_child: Vec<Option<(usize, usize)>> = vec![None; children];
        let mut retired: HashMap<usize, String> = HashMap::new();
        let mut station = 0usize;
        // The readings grouped by station, stations in the order they appear.
        let mut order: Vec<&str> = Vec::new();
        let mut groups: HashMap<&str, Vec<usize>> = HashMap::new();
        for &i in kept {
            let s = readings[i].station.as_str();
            groups.entry(s).or_insert_with(|| {
                order.push(s);
                Vec::new()
            });
            if let Some(g) = groups.get_mut(s) {
                g.push(i);
            }
        }
        for s in order {
            let group = &groups[s];
            if let Some(&v) = var.get(s) {
                if !matches!(script.vars()[v].role, Role::Station(_)) {
                    return Err(SurveyError::StationIsPoint(s.to_string()));
                }
            } else {
                // A new station: its approximate pose from the points known
                // before it.
                let known: Vec<(usize, usize)> = group
                    .iter()
                    .filter_map(|&i| var.get(readings[i].point.as_str()).map(|&v| (i, v)))
                    .filter(|&(_, v)| !matches!(script.vars()[v].role, Role::Station(_)))
                    .collect();
                let guess = resection(&model, &script, readings, &known).ok_or_else(|| {
                    SurveyError::TooFewKnown {
                        station: s.to_string(),
                        known: known.len(),
                    }
                })?;
                let v = script.add_station(guess);
                script.retire(station);
                station = v;
                var.insert(s, v);
            }
            let sv = var[s];
            for &i in group {
                let r = &readings[i];
                let p = r.point.as_str();
                if p == s {
                    return Err(SurveyError::StationIsPoint(s.to_string()));
                }
                if let Some(newer) = retired.get(&var.get(p).copied().unwrap_or(usize::MAX)) {
                    return Err(SurveyError::Replaced {
                        point: p.to_string(),
                        newer: newer.clone(),
                    });
                }
                let pv = match var.get(p) {
                    Some(&v) => {
                        if matches!(script.vars()[v].role, Role::Station(_)) {
                            return Err(SurveyError::StationIsPoint(p.to_string()));
                        }
                        v
                    }
                    None => {
                        let control = controls.iter().find(|c| c.name == p);
                        let role = match child_spot(p) {
                            Some((c, _)) => Role::Child(c),
                            None => Role::Target(script.vars().len()),
                        };
                        let (guess, sigma) = match control {
                            Some(c) => (model.point_at(c.position, c.z), Some(c.sigma_m)),
                            None => {
                                let z = r.observation(&model);
                                (
                                    model.forward(script.vars()[sv].truth.as_slice(), z.as_slice()),
                                    None,
                                )
                            }
                        };
                        if let Some((c, spot)) = child_spot(p) {
                            if let Some((old, _)) = current_child[c] {
                                script.retire(old);
                                retired.insert(old, p.to_string());
                            }
                            let v = script.add_point(role, guess, sigma);
                            current_child[c] = Some((v, spot));
                            var.insert(p, v);
                            v
                        } else {
                            let v = script.add_point(role, guess, sigma);
                            var.insert(p, v);
                            v
                        }
                    }
                };
                script.observe(sv, pv);
            }
        }
        let mut names = vec![String::new(); script.vars().len()];
        for (name, &v) in &var {
            names[v] = (*name).to_string();
        }
        let mut built = Self {
            script,
            names,
            order: Vec::new(),
        };
        built.order = built.measured(readings, kept);
        Ok(built)
    }

    /// The kept readings' observations, in the script's order.
    fn values(&self, readings: &[Reading]) -> Vec<DVector<f64>> {
        let model = *self.script.model();
        self.order
            .iter()
            .map(|&i| readings[i].observation(&model))
            .collect()
    }

    /// The reading of every measurement of the script, in order.
    fn measured(&self, readings: &[Reading], kept: &[usize]) -> Vec<usize> {
        let mut index: HashMap<(&str, &str), Vec<usize>> = HashMap::new();
        for &i in kept {
            let r = &readings[i];
            index
                .entry((r.station.as_str(), r.point.as_str()))
                .or_default()
                .push(i);
        }
        let mut used: HashMap<(&str, &str), usize> = HashMap::new();
        let mut out = Vec::new();
        for e in self.script.events() {
            if let super::script::Event::Observe { station, point } = *e {
                let key = (self.names[station].as_str(), self.names[point].as_str());
                let n = used.entry(key).or_insert(0);
                if let Some(&i) = index.get(&key).and_then(|v| v.get(*n)) {
                    out.push(i);
                }
                *n += 1;
            }
        }
        out
    }

    fn error(&self, e: NetworkError) -> SurveyError {
        match e {
            NetworkError::Underdetermined(u) => {
                let name = self
                    .script
                    .vars()
                    .iter()
                    .position(|v| v.role == u.0)
                    .map_or_else(|| u.to_string(), |v| self.names[v].clone());
                SurveyError::Underdetermined { name }
            }
            NetworkError::Singular | NetworkError::Values(..) => SurveyError::Singular,
        }
    }

    fn survey(
        &self,
        network: &Network,
        left_out: Vec<Blunder>,
        max_standardized: f64,
    ) -> Result<Survey, SurveyError> {
        let cov = network.smooth().map_err(|e| self.error(e))?;
        let mut stations = Vec::new();
        let mut points = Vec::new();
        for (v, var) in self.script.vars().iter().enumerate() {
            let value = network
                .value(v)
                .cloned()
                .unwrap_or_else(|| var.truth.clone());
            let n = value.len();
            let a = Adjusted {
                name: self.names[v].clone(),
                covariance: cov
                    .get(v)
                    .cloned()
                    .flatten()
                    .unwrap_or_else(|| DMatrix::zeros(n, n)),
                value,
            };
            match var.role {
                Role::Station(_) => stations.push(a),
                _ => points.push(a),
            }
        }
        Ok(Survey {
            stations,
            points,
            left_out,
            max_standardized,
        })
    }
}

/// A point in a station's frame and in the world.
type Pair = (DVector<f64>, DVector<f64>);

/// The approximate pose of a new station from its readings `known` (reading,
/// point unknown) to points with approximate coordinates: the 2D similarity
/// (rotation and shift) that best carries the readings' polar points onto
/// them; `None` with fewer than two.
fn resection(
    model: &Model,
    script: &Script,
    readings: &[Reading],
    known: &[(usize, usize)],
) -> Option<DVector<f64>> {
    if known.len() < 2 {
        return None;
    }
    let origin = model.station(Point::new(0.0, 0.0), 0.0);
    // Each reading's point in the station's frame, and where it is known.
    let pairs: Vec<Pair> = known
        .iter()
        .map(|&(i, v)| {
            let local = model.forward(origin.as_slice(), readings[i].observation(model).as_slice());
            (local, script.vars()[v].truth.clone())
        })
        .collect();
    let n = pairs.len() as f64;
    let mean = |f: &dyn Fn(&Pair) -> f64| pairs.iter().map(f).sum::<f64>() / n;
    let (lx, ly) = (mean(&|p| p.0[0]), mean(&|p| p.0[1]));
    let (wx, wy) = (mean(&|p| p.1[0]), mean(&|p| p.1[1]));
    let (mut dot, mut cross) = (0.0, 0.0);
    for (l, w) in &pairs {
        let (ax, ay) = (l[0] - lx, l[1] - ly);
        let (bx, by) = (w[0] - wx, w[1] - wy);
        dot += ax * bx + ay * by;
        cross += ax * by - ay * bx;
    }
    if dot == 0.0 && cross == 0.0 {
        return None;
    }
    let omega = cross.atan2(dot);
    let (s, c) = omega.sin_cos();
    let x = wx - (c * lx - s * ly);
    let y = wy - (s * lx + c * ly);
    let mut guess = model.station(Point::new(x, y), omega);
    if model.three_d() {
        // The station's height from the height differences.
        guess[2] = mean(&|p| p.1[2] - (p.0[2] - origin[2]));
    }
    Some(guess)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accuracy::Instrument;
    use crate::config::InstrumentConfig;
    use proptest::prelude::*;

    fn model(three_d: bool) -> Model {
        let config = InstrumentConfig {
            three_d,
            ..InstrumentConfig::default()
        };
        Model::new(Instrument::from_config(&config))
    }

    /// Noise-free readings of a chain of CPS cycles: from each station the
    /// children's new spots, then the next station (turned by `headings`)
    /// measures both children.
    /// One cycle: child 1's offset from the station, the next station's
    /// offset, its heading.
    type Move = ((f64, f64), (f64, f64), f64);

    fn chain(model: Model, moves: &[Move]) -> (Vec<Reading>, Vec<(String, DVector<f64>)>) {
        let mut readings = Vec::new();
        let mut stations = vec![(
            "S0000".to_string(),
            model.station(Point::new(0.0, 0.0), 0.3),
        )];
        for (k, &((c1x, c1y), (sx, sy), omega)) in moves.iter().enumerate() {
            let (name, station) = stations.last().cloned().expect("a station");
            // Child 1 moves near the station, child 2 stands beside it.
            let c1 = model.point(Point::new(station[0] + c1x, station[1] + c1y));
            let c2 = model.point(Point::new(station[0] - c1y, station[1] + c1x));
            let next = model.station(Point::new(station[0] + sx, station[1] + sy), omega);
            let spot = k + 1;
            let names = [format!("C1.{spot:04}"), format!("C2.{spot:04}")];
            for (n, c) in names.iter().zip([&c1, &c2]) {
                let z = model.observe(station.as_slice(), c.as_slice());
                readings.push(Reading::from_observation(&name, n, &model, z.as_slice()));
            }
            let next_name = format!("S{:04}", k + 1);
            for (n, c) in names.iter().zip([&c1, &c2]) {
                let z = model.observe(next.as_slice(), c.as_slice());
                readings.push(Reading::from_observation(
                    &next_name,
                    n,
                    &model,
                    z.as_slice(),
                ));
            }
            stations.push((next_name, next));
        }
        (readings, stations)
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(48))]

        /// Noise-free readings, named as a survey names them and in any
        /// instrument orientation, adjust to the stations that took them.
        #[test]
        fn exact_readings_give_the_true_stations(
            moves in proptest::collection::vec(
                ((2.0f64..8.0, 1.0f64..8.0), (-6.0f64..6.0, 3.0f64..9.0), -3.1f64..3.1),
                1..6,
            ),
            three_d in any::<bool>(),
        ) {
            let model = model(three_d);
            let (readings, stations) = chain(model, &moves);
            let datum = Datum {
                station: "S0000".into(),
                position: Point::new(0.0, 0.0),
                heading_rad: 0.3,
            };
            let survey = adjust_readings(model, &datum, &[], &readings, 0).unwrap();
            prop_assert!(survey.left_out.is_empty());
            prop_assert_eq!(survey.stations.len(), stations.len());
            for (name, truth) in &stations {
                let got = survey.get(name).unwrap();
                let d = (&got.value - truth).map(f64::abs);
                let n = d.len();
                // The heading modulo a turn.
                let turn = (got.value[n - 1] - truth[n - 1]).rem_euclid(std::f64::consts::TAU);
                prop_assert!(d.rows(0, n - 1).max() < 1e-6, "{name}: {d}");
                prop_assert!(turn.min(std::f64::consts::TAU - turn) < 1e-8, "{name}: {turn}");
            }
        }
    }

    #[test]
    fn a_station_with_one_known_point_is_too_few() {
        let model = model(false);
        let (mut readings, _) = chain(model, &[((3.0, 2.0), (1.0, 5.0), 0.0)]);
        // S0001 keeps only its reading to child 2.
        readings.retain(|r| !(r.station == "S0001" && r.point == "C1.0001"));
        let datum = Datum {
            station: "S0000".into(),
            position: Point::new(0.0, 0.0),
            heading_rad: 0.3,
        };
        let err = adjust_readings(model, &datum, &[], &readings, 0).unwrap_err();
        assert_eq!(
            err,
            SurveyError::TooFewKnown {
                station: "S0001".into(),
                known: 1
            }
        );
    }

    /// A simulated tunnel campaign's first 14 scans of readings (2 mm + 2 ppm,
    /// 1″), each within 2σ of the truth: accepted whole. Station S0013 sees its
    /// two children in nearly one direction, so the 1″ directions are nearly
    /// uncontrolled (redundancy near 1e-10), and rounding once made one 10.9σ.
    #[test]
    fn readings_that_fit_the_truth_are_accepted_whatever_their_redundancy() {
        let model = Model::new(Instrument::from_config(&InstrumentConfig::default()));
        let readings: Vec<Reading> = include_str!("testdata/tunnel-readings.csv")
            .lines()
            .skip(1)
            .map(|line| {
                let f: Vec<&str> = line.split(',').collect();
                let gon = |s: &str| s.parse::<f64>().unwrap() * std::f64::consts::PI / 200.0;
                Reading {
                    station: f[0].into(),
                    point: f[1].into(),
                    slope_distance_m: f[2].parse().unwrap(),
                    hz_rad: gon(f[3]),
                    zenith_rad: gon(f[4]),
                }
            })
            .collect();
        assert_eq!(readings.len(), 49);
        let datum = Datum {
            station: "S0000".into(),
            position: Point::new(4.05, 8.05),
            heading_rad: 0.0,
        };
        let survey = adjust_readings(model, &datum, &[], &readings, 0).unwrap();
        assert!(survey.left_out.is_empty(), "{:?}", survey.left_out);
        // The last station where the simulation stood it (scan 14).
        let s = survey.get("S0013").unwrap().position();
        assert!(s.distance(Point::new(36.05, 16.15)) < 0.01, "{s:?}");
    }

    #[test]
    fn child_markers_name_the_child_and_the_spot() {
        assert_eq!(child_spot("C1.0003"), Some((0, 3)));
        assert_eq!(child_spot("C12.7"), Some((11, 7)));
        for bad in ["C0.0001", "C1", "C1.", "C.1", "P1", "C1.0a", "c1.0001"] {
            assert_eq!(child_spot(bad), None, "{bad}");
        }
    }
}
