//! The adjustment of the whole CPS network (beyond the paper; docs/ACCURACY.md
//! "Closed networks"): every station, child point, target and control point
//! estimated together from every measurement so far, by weighted least squares.
//!
//! In: a [`Script`] (unknowns appear, are measured, are left behind) and the
//! measurements' values. Out: the *filtering* covariance of the current
//! unknowns (what is known now), and after [`Network::smooth`] the *smoothed*
//! covariance and estimate of every unknown (what all measurements together
//! say); with real (or simulated noisy) values, [`Network::adjust`] iterates
//! Gauss–Newton to the least-squares estimate and reports the residuals.
//!
//! The network is sparse: a station is measured only by the points near it and
//! the targets in sight. It is solved in the order the unknowns appear: each
//! unknown left behind is eliminated at once ([`elimination`]), so a measurement
//! costs work on the active unknowns only (the current station, the children's
//! points, the targets), never a refactoring of the whole network; the smoothing
//! pass ([`smooth`]) runs back through the eliminated unknowns in linear time.
//! The result is exact: the same as the dense batch adjustment
//! ([`super::batch_covariances`]), which the tests check on random networks with
//! loops.

mod elimination;
mod smooth;

use nalgebra::{DMatrix, DVector};
use thiserror::Error;

use self::elimination::Elimination;
use self::smooth::Marginals;
use super::model::Model;
use super::script::{Event, Role, Script, ScriptVar};

/// Gauss–Newton stops when no estimate moves by more than this, metres (or
/// radians): a micrometre, a thousandth of the instrument's noise.
pub const CONVERGED_M: f64 = 1e-6;

/// Why a network cannot be solved.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Error)]
pub enum NetworkError {
    /// The measurements do not fix an unknown (too few of them, or in a
    /// degenerate geometry).
    #[error("the measurements do not fix {0}: too few of them, or all in one line")]
    Underdetermined(Unknown),
    /// The measurements do not fix the current unknowns together.
    #[error("the measurements so far do not fix the network's current unknowns")]
    Singular,
    /// The values given do not match the script.
    #[error("{0} measurement values for {1} measurements")]
    Values(usize, usize),
}

/// An unknown named for people.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Unknown(pub Role);

impl std::fmt::Display for Unknown {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.0 {
            Role::Station(k) => write!(f, "station {k}"),
            Role::Child(i) => write!(f, "a point of child {}", i + 1),
            Role::Target(t) => write!(f, "target {}", t + 1),
        }
    }
}

/// One measurement of the network with its value.
#[derive(Debug, Clone, PartialEq)]
pub struct Measurement {
    /// The station's unknown.
    pub station: usize,
    /// The point's unknown.
    pub point: usize,
    /// The measured value (`[d, r]`, 3D `[s, r, ζ]`).
    pub z: DVector<f64>,
}

/// How well one measurement fits and is checked after an adjustment.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Fit {
    /// Its index among the measurements.
    pub measurement: usize,
    /// The largest standardized residual of its components, `|v| / σ_v`, over
    /// those with a redundancy number of at least [`MIN_TESTED_REDUNDANCY`].
    pub standardized: f64,
    /// The smallest redundancy number of its components (0: not checked by any
    /// other measurement, 1: fully checked).
    pub redundancy: f64,
}

/// How the measurements of one station are checked and fit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StationFit {
    /// The least redundancy number of its measurements, and the point that
    /// measurement went to.
    pub min_redundancy: (f64, Role),
    /// The largest standardized residual of its measurements, and the point.
    pub max_standardized: (f64, Role),
}

/// A campaign's network: its script, the measurements' values, the current
/// estimate of every unknown and the incremental solution.
#[derive(Debug, Clone)]
pub struct Network {
    script: Script,
    /// Estimate (linearisation point) of every unknown.
    values: Vec<DVector<f64>>,
    /// A control point's prior mean (its known coordinates).
    priors: Vec<Option<DVector<f64>>>,
    measurements: Vec<Measurement>,
    /// Events of the script applied (values read) and fed to the elimination.
    applied: usize,
    elim: Elimination,
    failed: Option<NetworkError>,
}

impl Network {
    /// An empty network on `script`; [`Self::extend`] or
    /// [`Self::extend_nominal`] applies the script's events.
    pub fn new(script: Script) -> Self {
        Self {
            script,
            values: Vec::new(),
            priors: Vec::new(),
            measurements: Vec::new(),
            applied: 0,
            elim: Elimination::default(),
            failed: None,
        }
    }

    /// The network of a whole script, every measurement at its nominal value
    /// (the planning case: the geometry decides the covariances).
    pub fn nominal(script: Script) -> Result<Self, NetworkError> {
        let mut n = Self::new(script);
        n.extend_nominal()?;
        Ok(n)
    }

    /// The script.
    pub fn script(&self) -> &Script {
        &self.script
    }

    /// The script, to add cycles to before the next [`Self::extend_nominal`].
    pub fn script_mut(&mut self) -> &mut Script {
        &mut self.script
    }

    /// The model.
    pub fn model(&self) -> Model {
        *self.script.model()
    }

    /// Every measurement so far.
    pub fn measurements(&self) -> &[Measurement] {
        &self.measurements
    }

    /// The current estimate of unknown `v`.
    pub fn value(&self, v: usize) -> Option<&DVector<f64>> {
        self.values.get(v)
    }

    /// Applies the script's new events with nominal values: every measurement
    /// what the instrument reads at the true geometry, every unknown and control
    /// point at its true place.
    pub fn extend_nominal(&mut self) -> Result<(), NetworkError> {
        let model = self.model();
        let vars = self.script.vars();
        let values: Vec<DVector<f64>> = self.script.events()[self.applied..]
            .iter()
            .filter_map(|e| match *e {
                Event::Observe { station, point } => Some(
                    model.observe(vars[station].truth.as_slice(), vars[point].truth.as_slice()),
                ),
                _ => None,
            })
            .collect();
        self.extend(values, |_, v| v.truth.clone(), |_, v| v.truth.clone())
    }

    /// Applies the script's new events with `values` (one per new measurement,
    /// in order), each new unknown starting at `guess` and each control point
    /// known at `prior`.
    pub fn extend(
        &mut self,
        values: Vec<DVector<f64>>,
        mut guess: impl FnMut(usize, &ScriptVar) -> DVector<f64>,
        mut prior: impl FnMut(usize, &ScriptVar) -> DVector<f64>,
    ) -> Result<(), NetworkError> {
        if let Some(e) = self.failed {
            return Err(e);
        }
        let from = self.applied;
        let events = &self.script.events()[from..];
        let wanted = events
            .iter()
            .filter(|e| matches!(e, Event::Observe { .. }))
            .count();
        if wanted != values.len() {
            return Err(NetworkError::Values(values.len(), wanted));
        }
        let mut values = values.into_iter();
        for e in events {
            match *e {
                Event::New(v) => {
                    let var = &self.script.vars()[v];
                    if self.values.len() <= v {
                        self.values.resize(v + 1, DVector::zeros(0));
                        self.priors.resize(v + 1, None);
                    }
                    self.values[v] = guess(v, var);
                    self.priors[v] = var.control_sigma.map(|_| prior(v, var));
                }
                Event::Observe { station, point } => {
                    if let Some(z) = values.next() {
                        self.measurements.push(Measurement { station, point, z });
                    }
                }
                Event::Retire(_) => {}
            }
        }
        self.applied = self.script.events().len();
        let first = self.measurements.len() - wanted;
        let mut elim = std::mem::take(&mut self.elim);
        let r = self.feed(&mut elim, from, first);
        self.elim = elim;
        if let Err(e) = r {
            self.failed = Some(e);
        }
        r
    }

    /// Feeds events `from..applied` (whose first measurement is `measurement`)
    /// to `elim`, linearised at the current values.
    fn feed(
        &self,
        elim: &mut Elimination,
        from: usize,
        mut measurement: usize,
    ) -> Result<(), NetworkError> {
        let model = self.model();
        let vars = self.script.vars();
        for e in &self.script.events()[from..self.applied] {
            match *e {
                Event::New(v) => {
                    if vars[v].fixed {
                        continue;
                    }
                    elim.add(v, self.values[v].len());
                    if let (Some(sigma), Some(mean)) = (vars[v].control_sigma, &self.priors[v]) {
                        elim.add_prior(v, sigma, &(mean - &self.values[v]));
                    }
                }
                Event::Observe { .. } => {
                    let m = &self.measurements[measurement];
                    measurement += 1;
                    let (blocks, variance, r) = linearise(&model, &self.values, vars, m);
                    elim.add_measurement(&blocks, &variance, &r);
                }
                Event::Retire(v) => {
                    elim.eliminate(v).map_err(|s| self.singular(s.var))?;
                }
            }
        }
        elim.fold();
        Ok(())
    }

    fn singular(&self, var: Option<usize>) -> NetworkError {
        match var {
            Some(v) => NetworkError::Underdetermined(Unknown(self.script.vars()[v].role)),
            None => NetworkError::Singular,
        }
    }

    /// The filtering covariance of the current unknown `v` (every measurement so
    /// far; `None` when `v` is not current).
    pub fn current_covariance(&self, v: usize) -> Result<Option<DMatrix<f64>>, NetworkError> {
        let Some(o) = self.elim.offset(v) else {
            return Ok(None);
        };
        let (cov, _) = self.elim.solve_active().map_err(|s| self.singular(s.var))?;
        let d = self.values[v].len();
        Ok(Some(cov.view((o, o), (d, d)).into_owned()))
    }

    /// The smoothed covariance of every unknown (every measurement at once),
    /// indexed like the script's unknowns (`None`: the fixed first station).
    pub fn smooth(&self) -> Result<Vec<Option<DMatrix<f64>>>, NetworkError> {
        let m =
            smooth::smooth(&self.elim, self.values.len(), &[]).map_err(|s| self.singular(s.var))?;
        Ok(m.cov)
    }

    /// Gauss–Newton on the whole network from the current estimates, at most
    /// `iterations` times: each pass linearises every measurement at the current
    /// estimates, solves, and moves every estimate ([`Self::fits`] then tells
    /// how every measurement fits).
    /// Returns the largest correction of the last pass.
    pub fn adjust(&mut self, iterations: usize) -> Result<f64, NetworkError> {
        let ds = self.model().station_dim();
        let mut last = f64::INFINITY;
        for _ in 0..iterations.max(1) {
            let mut elim = Elimination::default();
            self.feed(&mut elim, 0, 0)?;
            let m =
                smooth::smooth(&elim, self.values.len(), &[]).map_err(|s| self.singular(s.var))?;
            last = 0.0;
            for (v, d) in m.delta.iter().enumerate() {
                let Some(d) = d else { continue };
                self.values[v] += d;
                if matches!(self.script.vars()[v].role, Role::Station(_)) {
                    self.values[v][ds - 1] = wrap(self.values[v][ds - 1]);
                }
                last = last.max(d.amax());
            }
            self.elim = elim;
            if last < CONVERGED_M {
                break;
            }
        }
        let mut elim = Elimination::default();
        self.feed(&mut elim, 0, 0)?;
        self.elim = elim;
        Ok(last)
    }

    /// The fit of every station's measurements ([`Self::fits`]), by station
    /// number (`None` for a station that measured nothing, as the first may).
    pub fn station_fits(&self) -> Result<Vec<Option<StationFit>>, NetworkError> {
        let fits = self.fits()?;
        let stations = self.script.stations();
        let mut index = vec![usize::MAX; self.values.len()];
        for (k, &v) in stations.iter().enumerate() {
            if v < index.len() {
                index[v] = k;
            }
        }
        let vars = self.script.vars();
        let mut out: Vec<Option<StationFit>> = vec![None; stations.len()];
        for f in fits {
            let m = &self.measurements[f.measurement];
            let Some(&k) = index.get(m.station).filter(|&&k| k != usize::MAX) else {
                continue;
            };
            let role = vars[m.point].role;
            let e = out[k].get_or_insert(StationFit {
                min_redundancy: (f.redundancy, role),
                max_standardized: (f.standardized, role),
            });
            if f.redundancy < e.min_redundancy.0 {
                e.min_redundancy = (f.redundancy, role);
            }
            if f.standardized > e.max_standardized.0 {
                e.max_standardized = (f.standardized, role);
            }
        }
        Ok(out)
    }

    /// The fit of every measurement at the current estimates: standardized
    /// residuals and redundancy numbers from `Q_vv = R − H Σ Hᵀ`.
    pub fn fits(&self) -> Result<Vec<Fit>, NetworkError> {
        let model = self.model();
        let vars = self.script.vars();
        let mut pairs = vec![Vec::new(); self.values.len()];
        for m in &self.measurements {
            pairs[m.station].push(m.point);
            pairs[m.point].push(m.station);
        }
        let marg: Marginals = smooth::smooth(&self.elim, self.values.len(), &pairs)
            .map_err(|s| self.singular(s.var))?;
        let (ds, dp) = (model.station_dim(), model.point_dim());
        let mut out = Vec::with_capacity(self.measurements.len());
        for (i, m) in self.measurements.iter().enumerate() {
            let (blocks, variance, r) = linearise(&model, &self.values, vars, m);
            let k = r.len();
            // The joint covariance of the measurement's unknowns.
            let mut h = DMatrix::zeros(k, ds + dp);
            let mut q = DMatrix::zeros(ds + dp, ds + dp);
            for (v, hb) in &blocks {
                let (o, d) = if *v == m.station { (0, ds) } else { (ds, dp) };
                h.view_mut((0, o), (k, d)).copy_from(hb);
                if let Some(c) = &marg.cov[*v] {
                    q.view_mut((o, o), (d, d)).copy_from(c);
                }
            }
            let cross = marg
                .cross
                .get(&(m.station, m.point))
                .cloned()
                .or_else(|| marg.cross.get(&(m.point, m.station)).map(|c| c.transpose()));
            if let Some(c) = cross {
                q.view_mut((0, ds), (ds, dp)).copy_from(&c);
                q.view_mut((ds, 0), (dp, ds)).copy_from(&c.transpose());
            }
            let qvv = DMatrix::from_diagonal(&variance) - &h * q * h.transpose();
            let mut fit = Fit {
                measurement: i,
                standardized: 0.0,
                redundancy: 1.0,
            };
            for a in 0..k {
                let redundancy = if variance[a] > 0.0 {
                    (qvv[(a, a)] / variance[a]).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                fit.redundancy = fit.redundancy.min(redundancy);
                if redundancy >= MIN_TESTED_REDUNDANCY {
                    fit.standardized = fit.standardized.max(r[a].abs() / qvv[(a, a)].sqrt());
                }
            }
            out.push(fit);
        }
        Ok(out)
    }
}

/// The least redundancy number (the share of a component's variance left in
/// its residual) at which its standardized residual is computed. Below it the
/// component is uncontrolled: its residual is nearly zero whatever it holds, and
/// `variance − h Q hᵀ` is a difference of nearly equal numbers whose rounding
/// outweighs it (a direction of 1″ among 2 mm distances over a few metres has a
/// redundancy near 1e-10; rounding made it 10.9σ). The reading is still tested
/// by its other components and by the residuals of the readings it moves.
pub const MIN_TESTED_REDUNDANCY: f64 = 1e-4;

/// The Jacobian blocks (per non-fixed unknown), noise variances and residual of
/// measurement `m` at `values`.
#[allow(clippy::type_complexity)]
fn linearise(
    model: &Model,
    values: &[DVector<f64>],
    vars: &[ScriptVar],
    m: &Measurement,
) -> (Vec<(usize, DMatrix<f64>)>, DVector<f64>, DVector<f64>) {
    let s = values[m.station].as_slice();
    let c = values[m.point].as_slice();
    let (hs, hc) = model.jacobians(s, c);
    let mut r = &m.z - model.observe(s, c);
    for a in 1..r.len() {
        r[a] = wrap(r[a]);
    }
    let variance = model.noise_of(m.z.as_slice()).diagonal();
    let mut blocks = Vec::with_capacity(2);
    if !vars[m.station].fixed {
        blocks.push((m.station, hs));
    }
    if !vars[m.point].fixed {
        blocks.push((m.point, hc));
    }
    (blocks, variance, r)
}

/// An angle in (−π, π].
pub(crate) fn wrap(a: f64) -> f64 {
    let t = std::f64::consts::TAU;
    let r = a.rem_euclid(t);
    if r > std::f64::consts::PI {
        r - t
    } else {
        r
    }
}

#[cfg(test)]
mod tests;
