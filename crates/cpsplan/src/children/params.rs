//! The parameters of the CPS planning of one step: the children's size, the
//! instrument's range limits and the weights of Eq. (2).

use super::placement::Eq2;
use crate::config::{ChildStrategy, Config};
use crate::sensing::LinkRule;

/// The rule by which a station measures targets and control points: the
/// instrument's own range limits (not the children's link range: a total station
/// measures a prism far beyond the scanner's range) and the links'
/// line-of-sight clearance.
pub fn target_rule(config: &Config) -> LinkRule {
    let (min, max) = config.instrument.range_m();
    LinkRule {
        min,
        max,
        clearance: config.children.sight_clearance,
    }
}

/// Parameters of a cycle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CycleParams {
    /// Radius of every child, metres.
    pub child_radius: f64,
    /// Radius of every child's marker, metres: no line of sight to another
    /// child passes nearer to it.
    pub marker_radius: f64,
    /// The instrument's range limits for parent–child links.
    pub link: LinkRule,
    /// The instrument's range limits for measuring targets and control points
    /// (its own range; the line-of-sight clearance of the links).
    pub targets: LinkRule,
    /// Eq. (2) weights and targets (already set for the strategy: `angle` and
    /// `distance` divide the other weight by 100).
    pub eq2: Eq2,
    /// How the children's spots are chosen.
    pub strategy: ChildStrategy,
    /// Strategy `min-error`: mm of predicted σ per metre of child travel.
    pub travel_weight: f64,
}

impl CycleParams {
    /// The cycle parameters of a configuration: the children's radius, the link
    /// range (its maximum defaults to the scanner's range), Eq. (2) with θt in
    /// radians.
    pub fn from_config(config: &Config) -> Self {
        let c = &config.children;
        let (min, max) = config.link_range();
        Self {
            child_radius: c.radius,
            marker_radius: c.marker_radius,
            // The instrument's own limits bound the link too.
            link: LinkRule {
                min,
                max,
                clearance: c.sight_clearance,
            },
            targets: target_rule(config),
            eq2: Eq2 {
                alpha_c: c.alpha_c
                    * if c.strategy == ChildStrategy::Distance {
                        0.01
                    } else {
                        1.0
                    },
                beta_c: c.beta_c
                    * if c.strategy == ChildStrategy::Angle {
                        0.01
                    } else {
                        1.0
                    },
                theta_t: c.theta_t_deg.to_radians(),
                d_t: c.d_t,
                clearance_cap: c.clearance_cap,
            },
            strategy: c.strategy,
            travel_weight: c.travel_weight,
        }
    }
}
