//! A network's geometry as the sequence of what the instrument does: unknowns
//! appear (a station, a child's point, a target), measurements are taken, and
//! unknowns are left behind (a station the parent left, a point a child left).
//! The batch adjustment, the sparse network adjustment and the Monte Carlo
//! estimator all read a campaign in this one order.
//!
//! Per cycle, with the parent at station `k` (docs/ACCURACY.md "The chain"):
//! 1. targets left here are measured from station `k`;
//! 2. each child that moves leaves its old point (never measured again) and its
//!    new point is measured from station `k`;
//! 3. station `k + 1` appears and measures every child's point, then every
//!    target in sight (a control point enters with its known coordinates, a free
//!    target seen for the first time gets its point from this measurement);
//! 4. station `k` is left.
//!
//! The first station is known exactly (the datum).

use nalgebra::DVector;

use super::geometry::{CycleGeometry, NetworkGeometry, TargetPoint};
use super::model::Model;
use crate::geom::Point;

/// What an unknown of the network is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Role {
    /// Station `k` of the parent (0 is the first, known exactly).
    Station(usize),
    /// A point where child `i` stood.
    Child(usize),
    /// Target or control point `t`.
    Target(usize),
}

/// One unknown: its role, where it truly is, and a control point's prior.
#[derive(Debug, Clone, PartialEq)]
pub struct ScriptVar {
    /// What it is.
    pub role: Role,
    /// Its nominal (true) state in the model's layout.
    pub truth: DVector<f64>,
    /// A control point's standard deviation of each coordinate, metres.
    pub control_sigma: Option<f64>,
    /// Known exactly (the first station).
    pub fixed: bool,
}

/// One event of the script.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Event {
    /// Unknown `v` appears (a control point with its prior).
    New(usize),
    /// Station `station` measures point `point`.
    Observe {
        /// The station's unknown.
        station: usize,
        /// The point's unknown.
        point: usize,
    },
    /// Unknown `v` is never measured again.
    Retire(usize),
}

/// A network's unknowns and events, built cycle by cycle.
#[derive(Debug, Clone)]
pub struct Script {
    model: Model,
    vars: Vec<ScriptVar>,
    events: Vec<Event>,
    targets: Vec<TargetPoint>,
    /// The unknown of each target once it appeared.
    target_vars: Vec<Option<usize>>,
    /// The unknown of each child's current point.
    child_vars: Vec<Option<usize>>,
    /// The unknown of each station, in order.
    stations: Vec<usize>,
    /// The index of the first event of each cycle.
    cycle_starts: Vec<usize>,
}

impl Script {
    /// A network starting at `start` (known exactly) with `children` children
    /// and the `targets` known so far.
    pub fn new(model: Model, start: Point, children: usize, targets: &[TargetPoint]) -> Self {
        let mut s = Self::with_datum(model, model.station(start, 0.0), children);
        for &t in targets {
            s.add_target(t);
        }
        s
    }

    /// An empty script whose first station, known exactly, is `datum` (the
    /// model's station vector, [`Model::station`]): the start of a network built
    /// reading by reading ([`Self::add_station`], [`Self::add_point`],
    /// [`Self::observe`], [`Self::retire`]).
    pub fn with_datum(model: Model, datum: DVector<f64>, children: usize) -> Self {
        let mut s = Self {
            model,
            vars: Vec::new(),
            events: Vec::new(),
            targets: Vec::new(),
            target_vars: Vec::new(),
            child_vars: vec![None; children],
            stations: Vec::new(),
            cycle_starts: Vec::new(),
        };
        let v = s.var(Role::Station(0), datum, None, true);
        s.stations.push(v);
        s.events.push(Event::New(v));
        s
    }

    /// Sets up the next station, its unknown starting at `guess`; returns the
    /// unknown.
    pub fn add_station(&mut self, guess: DVector<f64>) -> usize {
        let k = self.stations.len();
        let v = self.var(Role::Station(k), guess, None, false);
        self.stations.push(v);
        self.events.push(Event::New(v));
        v
    }

    /// A new point of `role` starting at `guess` (a control point with the σ
    /// of its known coordinates, which are `guess`); returns its unknown.
    pub fn add_point(
        &mut self,
        role: Role,
        guess: DVector<f64>,
        control_sigma: Option<f64>,
    ) -> usize {
        let v = self.var(role, guess, control_sigma, false);
        self.events.push(Event::New(v));
        v
    }

    /// A measurement from the unknown `station` to the unknown `point`.
    pub fn observe(&mut self, station: usize, point: usize) {
        self.events.push(Event::Observe { station, point });
    }

    /// Leaves the unknown `v` behind: nothing measures it after this.
    pub fn retire(&mut self, v: usize) {
        self.events.push(Event::Retire(v));
    }

    /// The script of a whole network.
    pub fn of(model: Model, net: &NetworkGeometry) -> Self {
        let mut s = Self::new(model, net.start, net.children(), &net.targets);
        s.sight_here(&net.at_start);
        for c in &net.cycles {
            s.cycle(c);
        }
        s
    }

    /// The model.
    pub fn model(&self) -> &Model {
        &self.model
    }

    /// Every unknown, by index.
    pub fn vars(&self) -> &[ScriptVar] {
        &self.vars
    }

    /// Every event, in order.
    pub fn events(&self) -> &[Event] {
        &self.events
    }

    /// The unknown of each station, in order (0 is the first, fixed).
    pub fn stations(&self) -> &[usize] {
        &self.stations
    }

    /// The index into [`Self::events`] of each cycle's first event, in order:
    /// the events before the first belong to the first station alone.
    pub fn cycle_starts(&self) -> &[usize] {
        &self.cycle_starts
    }

    /// The unknown of target `t`, once it appeared.
    pub fn target_var(&self, t: usize) -> Option<usize> {
        self.target_vars.get(t).copied().flatten()
    }

    /// Number of targets registered.
    pub fn target_count(&self) -> usize {
        self.targets.len()
    }

    /// Registers a target (given or left by the team); returns its index.
    pub fn add_target(&mut self, t: TargetPoint) -> usize {
        self.targets.push(t);
        self.target_vars.push(None);
        self.targets.len() - 1
    }

    fn var(&mut self, role: Role, truth: DVector<f64>, control: Option<f64>, fixed: bool) -> usize {
        self.vars.push(ScriptVar {
            role,
            truth,
            control_sigma: control,
            fixed,
        });
        self.vars.len() - 1
    }

    fn station(&self) -> usize {
        *self.stations.last().expect("the first station exists")
    }

    /// The targets `sighted` measured from the current station.
    pub fn sight_here(&mut self, sighted: &[usize]) {
        let station = self.station();
        self.sight(station, sighted);
    }

    fn sight(&mut self, station: usize, sighted: &[usize]) {
        for &t in sighted {
            let Some(&target) = self.targets.get(t) else {
                continue;
            };
            let point = match self.target_vars[t] {
                Some(v) => v,
                None => {
                    let truth = self.model.point_at(target.position, target.z);
                    let v = self.var(Role::Target(t), truth, target.control_sigma, false);
                    self.target_vars[t] = Some(v);
                    self.events.push(Event::New(v));
                    v
                }
            };
            self.events.push(Event::Observe { station, point });
        }
    }

    /// One cycle (the module's steps 1–4).
    pub fn cycle(&mut self, c: &CycleGeometry) {
        self.cycle_starts.push(self.events.len());
        let from = self.station();
        self.sight(from, &c.here);
        for (i, &p) in c.children.iter().enumerate() {
            if i >= self.child_vars.len() {
                break;
            }
            if c.moved.get(i).copied().unwrap_or(true) || self.child_vars[i].is_none() {
                if let Some(old) = self.child_vars[i] {
                    self.events.push(Event::Retire(old));
                }
                let v = self.var(Role::Child(i), self.model.point(p), None, false);
                self.child_vars[i] = Some(v);
                self.events.push(Event::New(v));
                self.events.push(Event::Observe {
                    station: from,
                    point: v,
                });
            }
        }
        let k = self.stations.len();
        let to = self.var(Role::Station(k), self.model.station(c.to, 0.0), None, false);
        self.stations.push(to);
        self.events.push(Event::New(to));
        for v in self.child_vars.clone().into_iter().flatten() {
            self.events.push(Event::Observe {
                station: to,
                point: v,
            });
        }
        self.sight(to, &c.sighted);
        self.events.push(Event::Retire(from));
    }
}
