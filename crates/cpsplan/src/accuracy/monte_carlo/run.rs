//! One noisy realisation of a network: every measurement of the script drawn
//! with the instrument's noise (and every control point's known coordinates
//! with theirs), the stations estimated as the team estimates them in the field
//! (the *filtering* estimates: each moving child's point from the estimated
//! station, each new station with the points by Gauss–Newton on its measurements
//! and the points' prior), then, optionally, the whole network adjusted at once
//! from the same readings (the *smoothed* estimates).

use nalgebra::{DMatrix, DVector};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};

use super::super::chain::{invert_spd, Chain, ChainError};
use super::super::geometry::NetworkGeometry;
use super::super::model::Model;
use super::super::network::{wrap, Network, StationFit};
use super::super::script::{Event, Role, Script};

/// Gauss–Newton iterations per resection at most (from the drifted guess the noise
/// is millimetric and two or three suffice).
const ITERATIONS: usize = 8;

/// Gauss–Newton passes of the whole network at most.
const NETWORK_ITERATIONS: usize = 12;

/// The analytic prior of one resection: the information of the points (children,
/// then targets in `order`) and that order.
pub(super) struct Prior {
    info: DMatrix<f64>,
    order: Vec<usize>,
}

/// The analytic priors of every resection of `net`, shared by all runs.
pub(super) fn priors(model: &Model, net: &NetworkGeometry) -> Result<Vec<Prior>, ChainError> {
    let n = net.children();
    let mut chain = Chain::new(*model, net.start, n);
    for &t in &net.targets {
        chain.add_target(t);
    }
    chain.sight_here(&net.at_start)?;
    let mut out = Vec::with_capacity(net.cycles.len());
    let dp = model.point_dim();
    for c in &net.cycles {
        chain.sight_here(&c.here)?;
        chain.cycle_sighting(c.to, &c.children, &c.moved, &c.sighted)?;
        let info = chain.prior_info().clone();
        let targets = (info.nrows() / dp).saturating_sub(n);
        out.push(Prior {
            order: chain.target_order()[..targets].to_vec(),
            info,
        });
    }
    Ok(out)
}

/// The errors `[x, y, z, ω]` of every station after the first (one per cycle),
/// filtering and, when asked, smoothed.
pub(super) struct RunErrors {
    pub filtering: Vec<[f64; 4]>,
    pub smoothed: Option<Vec<[f64; 4]>>,
    /// With `fits`: every station's fit after the adjustment.
    pub fits: Option<Vec<Option<StationFit>>>,
    /// Every noisy reading, in the order of the script's Observe events.
    pub readings: Vec<DVector<f64>>,
}

/// One realisation (module doc).
pub(super) fn one_run(
    model: &Model,
    net: &NetworkGeometry,
    script: &Script,
    priors: &[Prior],
    rng: &mut ChaCha8Rng,
    smooth: bool,
    fits: bool,
) -> RunErrors {
    let mut run = Run::new(model, script, net.children());
    for e in script.events() {
        run.event(*e, priors, rng);
    }
    let adjusted = smooth.then(|| run.smoothed(script, fits)).flatten();
    let (smoothed, fits) = match adjusted {
        Some((s, f)) => (Some(s), f),
        None => (None, None),
    };
    RunErrors {
        filtering: run.errors,
        smoothed,
        fits,
        readings: run.readings,
    }
}

/// The state of one realisation as the events go by.
struct Run<'a> {
    model: &'a Model,
    script: &'a Script,
    /// The latest estimate of every unknown.
    est: Vec<Option<DVector<f64>>>,
    /// A control point's known coordinates as drawn.
    prior: Vec<Option<DVector<f64>>>,
    /// Every reading, in the script's order.
    readings: Vec<DVector<f64>>,
    /// The station the parent stands on (estimated), and the one it moved to.
    station: usize,
    next: Option<usize>,
    /// The readings from the next station: (point, reading).
    next_readings: Vec<(usize, DVector<f64>)>,
    /// Each child's current point.
    child_var: Vec<Option<usize>>,
    /// Resections done.
    cycle: usize,
    errors: Vec<[f64; 4]>,
}

impl<'a> Run<'a> {
    fn new(model: &'a Model, script: &'a Script, children: usize) -> Self {
        let n = script.vars().len();
        Self {
            model,
            script,
            est: vec![None; n],
            prior: vec![None; n],
            readings: Vec::new(),
            station: 0,
            next: None,
            next_readings: Vec::new(),
            child_var: vec![None; children],
            cycle: 0,
            errors: Vec::new(),
        }
    }

    fn truth(&self, v: usize) -> &DVector<f64> {
        &self.script.vars()[v].truth
    }

    fn noisy(&self, s: usize, c: usize, rng: &mut ChaCha8Rng) -> DVector<f64> {
        let (s, c) = (self.truth(s).as_slice(), self.truth(c).as_slice());
        let mut z = self.model.observe(s, c);
        let r = self.model.noise(s, c);
        for i in 0..z.len() {
            let e: f64 = StandardNormal.sample(rng);
            z[i] += e * r[(i, i)].sqrt();
        }
        z
    }

    fn event(&mut self, e: Event, priors: &[Prior], rng: &mut ChaCha8Rng) {
        match e {
            Event::New(v) => {
                let var = &self.script.vars()[v];
                match var.role {
                    Role::Station(0) => {
                        self.station = v;
                        self.est[v] = Some(var.truth.clone());
                    }
                    Role::Station(_) => self.next = Some(v),
                    Role::Child(i) => self.child_var[i] = Some(v),
                    Role::Target(_) => {
                        if let Some(sigma) = var.control_sigma {
                            let mut p = var.truth.clone();
                            for a in 0..p.len() {
                                let e: f64 = StandardNormal.sample(rng);
                                p[a] += e * sigma;
                            }
                            self.est[v] = Some(p.clone());
                            self.prior[v] = Some(p);
                        }
                    }
                }
            }
            Event::Observe { station, point } => {
                let z = self.noisy(station, point, rng);
                self.readings.push(z.clone());
                if Some(station) == self.next {
                    self.next_readings.push((point, z));
                } else {
                    self.measure_from_station(station, point, &z);
                }
            }
            Event::Retire(v) => {
                if v == self.station {
                    if let Some(next) = self.next.take() {
                        self.resect(next, priors.get(self.cycle));
                    }
                }
            }
        }
    }

    /// A point measured from the station the parent stands on: a new point from
    /// the estimated station; a control point's known coordinates combined with
    /// it (the station taken as known, as the first one is).
    fn measure_from_station(&mut self, station: usize, point: usize, z: &DVector<f64>) {
        let Some(s) = self.est[station].clone() else {
            return;
        };
        let m = self.model;
        let forward = m.forward(s.as_slice(), z.as_slice());
        match (&self.est[point], &self.prior[point]) {
            (None, _) => self.est[point] = Some(forward),
            (Some(_), Some(p)) => {
                let (_, fz) = m.forward_jacobians(s.as_slice(), z.as_slice());
                let pf = &fz * m.noise_of(z.as_slice()) * fz.transpose();
                let sigma = self.script.vars()[point].control_sigma.unwrap_or(1.0);
                let ip = DMatrix::identity(p.len(), p.len()) / (sigma * sigma);
                if let (Some(iff), Some(total)) = (
                    invert_spd(&pf),
                    invert_spd(&(&ip + invert_spd(&pf).unwrap_or_else(|| ip.clone()))),
                ) {
                    self.est[point] = Some(total * (&ip * p + iff * forward));
                }
            }
            // A point measured before, measured again from the same station:
            // its estimate stays (it does not happen in a campaign's script).
            (Some(_), None) => {}
        }
    }

    /// The new station `next` by resection on the points it measured, then the
    /// points it measured first from it.
    fn resect(&mut self, next: usize, prior: Option<&Prior>) {
        let m = self.model;
        let ds = m.station_dim();
        let Some(prior) = prior else { return };
        let mut layout: Vec<usize> = self.child_var.iter().flatten().copied().collect();
        for &t in &prior.order {
            if let Some(v) = self.script.target_var(t) {
                layout.push(v);
            }
        }
        let readings = std::mem::take(&mut self.next_readings);
        let known: Vec<(usize, DVector<f64>)> = readings
            .iter()
            .filter_map(|(p, z)| {
                let i = layout.iter().position(|v| v == p)?;
                self.est[*p].is_some().then(|| (i, z.clone()))
            })
            .collect();
        let prior_points: Vec<DVector<f64>> = layout
            .iter()
            .map(|&v| self.est[v].clone().unwrap_or_else(|| self.truth(v).clone()))
            .collect();
        let old = self.station;
        let guess = drifted(
            m,
            self.truth(old),
            self.est[old].as_ref().unwrap_or_else(|| self.truth(old)),
            self.truth(next),
        );
        let (u, refined) = resect(m, &guess, &prior_points, &prior.info, &known);
        for (&v, r) in layout.iter().zip(refined) {
            self.est[v] = Some(r);
        }
        self.est[next] = Some(u);
        self.station = next;
        self.cycle += 1;
        for (p, z) in readings {
            if self.est[p].is_none() {
                self.measure_from_station(next, p, &z);
            }
        }
        let est = self.est[next].as_ref().expect("just set");
        self.errors.push(error_of(m, est, self.truth(next), ds));
    }

    /// The whole network adjusted from the same readings, starting at the
    /// filtering estimates, with every station's fit when asked; `None` when it
    /// cannot be solved.
    #[allow(clippy::type_complexity)]
    fn smoothed(
        &self,
        script: &Script,
        fits: bool,
    ) -> Option<(Vec<[f64; 4]>, Option<Vec<Option<StationFit>>>)> {
        let m = self.model;
        let mut net = Network::new(script.clone());
        net.extend(
            self.readings.clone(),
            |i, v| self.est[i].clone().unwrap_or_else(|| v.truth.clone()),
            |i, v| self.prior[i].clone().unwrap_or_else(|| v.truth.clone()),
        )
        .ok()?;
        net.adjust(NETWORK_ITERATIONS).ok()?;
        let ds = m.station_dim();
        let errors = script.stations()[1..]
            .iter()
            .map(|&v| Some(error_of(m, net.value(v)?, &script.vars()[v].truth, ds)))
            .collect::<Option<Vec<[f64; 4]>>>()?;
        let fits = if fits { net.station_fits().ok() } else { None };
        Some((errors, fits))
    }
}

/// The error `[x, y, z, ω]` of station estimate `est` of the true `truth`.
fn error_of(model: &Model, est: &DVector<f64>, truth: &DVector<f64>, ds: usize) -> [f64; 4] {
    let mut e = est - truth;
    e[ds - 1] = wrap(e[ds - 1]);
    if model.three_d() {
        [e[0], e[1], e[2], e[ds - 1]]
    } else {
        [e[0], e[1], 0.0, e[ds - 1]]
    }
}

/// `truth_new` moved by the rigid motion that takes `truth_old` to `estimate_old`.
fn drifted(
    model: &Model,
    truth_old: &DVector<f64>,
    estimate_old: &DVector<f64>,
    truth_new: &DVector<f64>,
) -> DVector<f64> {
    let ds = model.station_dim();
    let dw = estimate_old[ds - 1] - truth_old[ds - 1];
    let (s, c) = dw.sin_cos();
    let (dx, dy) = (truth_new[0] - truth_old[0], truth_new[1] - truth_old[1]);
    let mut u = truth_new.clone();
    u[0] = estimate_old[0] + c * dx - s * dy;
    u[1] = estimate_old[1] + s * dx + c * dy;
    if model.three_d() {
        u[2] = truth_new[2] + estimate_old[2] - truth_old[2];
    }
    u[ds - 1] = truth_new[ds - 1] + dw;
    u
}

/// Gauss–Newton on the new station `u` and the points `c`: the readings `obs`
/// (point index, reading) and the points' prior `prior_points` with information
/// `prior`; starts from `guess` for the station.
fn resect(
    model: &Model,
    guess: &DVector<f64>,
    prior_points: &[DVector<f64>],
    prior: &DMatrix<f64>,
    obs: &[(usize, DVector<f64>)],
) -> (DVector<f64>, Vec<DVector<f64>>) {
    let (ds, dp, m) = (model.station_dim(), model.point_dim(), model.obs_dim());
    let n = prior_points.len();
    let size = ds + n * dp;
    let mut x = DVector::zeros(size);
    x.rows_mut(0, ds).copy_from(guess);
    for (i, p) in prior_points.iter().enumerate() {
        x.rows_mut(ds + i * dp, dp).copy_from(p);
    }
    let mut c0 = DVector::zeros(n * dp);
    for (i, p) in prior_points.iter().enumerate() {
        c0.rows_mut(i * dp, dp).copy_from(p);
    }
    for _ in 0..ITERATIONS {
        let mut info = DMatrix::zeros(size, size);
        let mut rhs = DVector::zeros(size);
        info.view_mut((ds, ds), (n * dp, n * dp)).copy_from(prior);
        let dc = &c0 - x.rows(ds, n * dp);
        let prior_rhs = prior * dc;
        let mut r = rhs.rows_mut(ds, n * dp);
        r += prior_rhs;
        let u = x.rows(0, ds).into_owned();
        for (i, z) in obs {
            let o = ds + i * dp;
            let c = x.rows(o, dp).into_owned();
            let (hs, hc) = model.jacobians(u.as_slice(), c.as_slice());
            let w = invert_spd(&model.noise(u.as_slice(), c.as_slice()))
                .unwrap_or_else(|| DMatrix::identity(m, m));
            let mut res = z - model.observe(u.as_slice(), c.as_slice());
            for a in 1..m {
                res[a] = wrap(res[a]);
            }
            let mut h = DMatrix::zeros(m, size);
            h.view_mut((0, 0), (m, ds)).copy_from(&hs);
            h.view_mut((0, o), (m, dp)).copy_from(&hc);
            let ht_w = h.transpose() * &w;
            info += &ht_w * &h;
            rhs += ht_w * res;
        }
        let Some(step) = info.cholesky().map(|c| c.solve(&rhs)) else {
            break;
        };
        x += &step;
        if step.amax() < 1e-12 {
            break;
        }
    }
    let points = (0..n)
        .map(|i| x.rows(ds + i * dp, dp).into_owned())
        .collect();
    (x.rows(0, ds).into_owned(), points)
}
