//! A campaign as ROS 2 messages, whatever carries them: an MCAP file
//! ([`super::mcap_out`], `--mcap-out`) or a live node's publishers
//! (`cpsplan ros`); docs/USER-GUIDE.md "Robot software".
//!
//! Topics, frame `map`:
//! - `/map` (`nav_msgs/OccupancyGrid`): the knowledge map;
//! - `/cpsplan/scans` (`sensor_msgs/PointCloud2`): scans' registered points
//!   (`x`, `y`, `z` float32);
//! - `/cpsplan/stations` (`geometry_msgs/PoseWithCovarianceStamped`): scan
//!   stations with their covariance;
//! - `/cpsplan/path/parent`, `/cpsplan/path/child<n>` (`nav_msgs/Path`): each
//!   robot's driven path so far;
//! - `/cpsplan/plan` (`visualization_msgs/MarkerArray`): a planning round:
//!   the candidates, the target, the children's spots;
//! - `/tf` (`tf2_msgs/TFMessage`): `map` → `parent` and `map` → `child<n>`.

use anyhow::Result;
use cpsplan::grid::CellState;
use cpsplan::mission::Step;
use cpsplan::{OccupancyGrid, Point};

use super::ros2::{marker, schema, Cdr, Marker, LINE_STRIP, SPHERE};

/// The frame every message is in.
const FRAME: &str = "map";

/// Nanoseconds of `hours` on the campaign clock.
pub fn clock_ns(hours: f64) -> u64 {
    (hours.max(0.0) * 3.6e12) as u64
}

/// Where messages go.
pub trait Outlet {
    /// Sends one message stamped `ns` on `topic`: `cdr` (with its
    /// encapsulation header) of type `kind` (`package/msg/Name`), whose
    /// `ros2msg` definition `schema` gives.
    fn send(
        &mut self,
        topic: &str,
        kind: &'static str,
        schema: fn() -> String,
        ns: u64,
        cdr: &[u8],
    ) -> Result<()>;
}

/// A campaign's messages into an [`Outlet`].
pub struct RosOut<O> {
    outlet: O,
    driven: Vec<Vec<Point>>,
}

impl<O: Outlet> RosOut<O> {
    /// Messages of a team of `children` children into `outlet`.
    pub fn with_outlet(outlet: O, children: usize) -> Self {
        Self {
            outlet,
            driven: vec![Vec::new(); children + 1],
        }
    }

    /// The outlet.
    pub fn outlet_mut(&mut self) -> &mut O {
        &mut self.outlet
    }

    /// Forgets the paths driven so far (before a campaign is replayed anew).
    pub fn forget_paths(&mut self) {
        self.driven.iter_mut().for_each(Vec::clear);
    }

    /// The outlet, given back.
    pub fn into_outlet(self) -> O {
        self.outlet
    }

    /// The knowledge map at `ns`.
    pub fn map(&mut self, ns: u64, knowledge: &OccupancyGrid) -> Result<()> {
        let g = knowledge.geometry();
        let mut c = Cdr::new();
        c.header(ns, FRAME);
        c.time(ns);
        c.f32(g.resolution as f32);
        c.u32(u32::try_from(g.width)?);
        c.u32(u32::try_from(g.height)?);
        c.pose(g.origin.x, g.origin.y, 0.0, g.yaw);
        let data: Vec<u8> = knowledge
            .cells()
            .iter()
            .map(|&s| match s {
                CellState::Free => 0u8,
                CellState::Occupied => 100,
                CellState::Unknown => 0xff,
            })
            .collect();
        c.bytes(&data);
        self.outlet.send(
            "/map",
            "nav_msgs/msg/OccupancyGrid",
            schema::occupancy_grid,
            ns,
            &c.into_bytes(),
        )
    }

    /// A scan's registered points at `ns`.
    pub fn scan(&mut self, ns: u64, points: &[[f64; 3]]) -> Result<()> {
        let mut c = Cdr::new();
        c.header(ns, FRAME);
        c.u32(1);
        c.u32(u32::try_from(points.len())?);
        c.len(3);
        for (k, name) in ["x", "y", "z"].iter().enumerate() {
            c.string(name);
            c.u32(4 * k as u32);
            c.u8(7); // FLOAT32
            c.u32(1);
        }
        c.u8(0); // little endian
        c.u32(12);
        c.u32(u32::try_from(points.len().saturating_mul(12))?);
        let mut data = Vec::with_capacity(points.len() * 12);
        for p in points {
            for v in p {
                data.extend_from_slice(&(*v as f32).to_le_bytes());
            }
        }
        c.bytes(&data);
        c.u8(1); // dense
        self.outlet.send(
            "/cpsplan/scans",
            "sensor_msgs/msg/PointCloud2",
            schema::point_cloud2,
            ns,
            &c.into_bytes(),
        )
    }

    /// A scan station at `ns`: position, heading and the position's
    /// covariance (m²), the heading's variance (rad²).
    pub fn station(
        &mut self,
        ns: u64,
        at: Point,
        heading: f64,
        covariance: [[f64; 2]; 2],
        heading_variance: f64,
    ) -> Result<()> {
        let mut c = Cdr::new();
        c.header(ns, FRAME);
        c.pose(at.x, at.y, 0.0, heading);
        let mut cov = [0.0; 36];
        cov[0] = covariance[0][0];
        cov[1] = covariance[0][1];
        cov[6] = covariance[1][0];
        cov[7] = covariance[1][1];
        cov[35] = heading_variance;
        for v in cov {
            c.f64(v);
        }
        self.outlet.send(
            "/cpsplan/stations",
            "geometry_msgs/msg/PoseWithCovarianceStamped",
            schema::pose_with_covariance_stamped,
            ns,
            &c.into_bytes(),
        )
    }

    /// A planning step and the knowledge map it planned on, stamped with the
    /// step's campaign clock.
    pub fn record(&mut self, step: &Step, knowledge: &OccupancyGrid) -> Result<()> {
        let ns = clock_ns(step.clock_h);
        self.map(ns, knowledge)?;
        self.step(ns, step)
    }

    /// A planning step at `ns`: the robots' paths so far, where they stand,
    /// and the round's plan.
    pub fn step(&mut self, ns: u64, step: &Step) -> Result<()> {
        self.drive(step);
        self.plan_state(ns, step)
    }

    /// Adds the paths driven after `step`'s scan to each robot's path, and
    /// sends nothing.
    pub fn drive(&mut self, step: &Step) {
        self.driven[0].extend(step.driven_path());
        for cycle in &step.movement.cycles {
            for (i, child) in cycle.children.iter().enumerate() {
                if let Some(d) = self.driven.get_mut(i + 1) {
                    d.extend(child.path.iter().copied());
                }
            }
        }
    }

    /// Where the robots stand after `step`, its plan and each robot's path
    /// so far, at `ns`.
    pub fn plan_state(&mut self, ns: u64, step: &Step) -> Result<()> {
        self.tf(ns, step)?;
        self.plan(ns, step)?;
        for r in 0..self.driven.len() {
            let topic = if r == 0 {
                "/cpsplan/path/parent".to_string()
            } else {
                format!("/cpsplan/path/child{r}")
            };
            let mut c = Cdr::new();
            c.header(ns, FRAME);
            c.len(self.driven[r].len());
            for p in &self.driven[r] {
                c.header(ns, FRAME);
                c.pose(p.x, p.y, 0.0, 0.0);
            }
            self.outlet.send(
                &topic,
                "nav_msgs/msg/Path",
                schema::path,
                ns,
                &c.into_bytes(),
            )?;
        }
        Ok(())
    }

    fn tf(&mut self, ns: u64, step: &Step) -> Result<()> {
        let mut frames = vec![("parent".to_string(), step.position)];
        for (i, &p) in step.children.iter().enumerate() {
            frames.push((format!("child{}", i + 1), p));
        }
        let mut c = Cdr::new();
        c.len(frames.len());
        for (name, p) in frames {
            c.header(ns, FRAME);
            c.string(&name);
            for v in [p.x, p.y, 0.0] {
                c.f64(v);
            }
            c.quaternion(0.0);
        }
        self.outlet.send(
            "/tf",
            "tf2_msgs/msg/TFMessage",
            schema::tf_message,
            ns,
            &c.into_bytes(),
        )
    }

    fn plan(&mut self, ns: u64, step: &Step) -> Result<()> {
        let mut markers = Vec::new();
        let target = step.movement.target;
        for (k, cand) in step.plan.candidates.iter().enumerate() {
            let chosen = Some(k) == target;
            markers.push(Marker {
                ns: "candidates".into(),
                id: i32::try_from(k).unwrap_or(i32::MAX),
                kind: SPHERE,
                at: [cand.position.x, cand.position.y, 0.0],
                scale: if chosen { [0.6; 3] } else { [0.3; 3] },
                color: if chosen {
                    [0.8, 0.1, 0.1, 1.0]
                } else {
                    [1.0, 0.7, 0.2, 0.8]
                },
                points: Vec::new(),
                text: String::new(),
            });
        }
        for (n, cycle) in step.movement.cycles.iter().enumerate() {
            for (i, child) in cycle.children.iter().enumerate() {
                markers.push(Marker {
                    ns: format!("child{}", i + 1),
                    id: i32::try_from(n).unwrap_or(i32::MAX),
                    kind: SPHERE,
                    at: [child.to.x, child.to.y, 0.0],
                    scale: [0.4; 3],
                    color: if i == 0 {
                        [0.6, 0.3, 0.9, 1.0]
                    } else {
                        [0.1, 0.8, 0.8, 1.0]
                    },
                    points: Vec::new(),
                    text: String::new(),
                });
            }
        }
        let route = step.driven_path();
        if route.len() > 1 {
            markers.push(Marker {
                ns: "parent_path".into(),
                id: 0,
                kind: LINE_STRIP,
                at: [0.0; 3],
                scale: [0.1, 0.0, 0.0],
                color: [0.1, 0.4, 0.9, 1.0],
                points: route.iter().map(|p| [p.x, p.y, 0.0]).collect(),
                text: String::new(),
            });
        }
        let mut c = Cdr::new();
        c.len(markers.len());
        for m in &markers {
            marker(&mut c, m, ns, FRAME);
        }
        self.outlet.send(
            "/cpsplan/plan",
            "visualization_msgs/msg/MarkerArray",
            schema::marker_array,
            ns,
            &c.into_bytes(),
        )
    }
}
