//! The parameters of the CPS planning of one step: the children's size, the
//! instrument's range limits and the weights of Eq. (2).

use super::placement::Eq2;
use crate::config::Config;
use crate::sensing::LinkRule;

/// Parameters of a cycle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CycleParams {
    /// Radius of every child, metres.
    pub child_radius: f64,
    /// The instrument's range limits for parent–child links.
    pub link: LinkRule,
    /// Eq. (2) weights and targets.
    pub eq2: Eq2,
}

impl CycleParams {
    /// The cycle parameters of a configuration: the children's radius, the link
    /// range (its maximum defaults to the scanner's range), Eq. (2) with θt in
    /// radians.
    pub fn from_config(config: &Config) -> Self {
        let c = &config.children;
        Self {
            child_radius: c.radius,
            link: LinkRule {
                min: c.min_range,
                max: c.max_range.unwrap_or(config.scanner.range),
                clearance: c.sight_clearance,
            },
            eq2: Eq2 {
                alpha_c: c.alpha_c,
                beta_c: c.beta_c,
                theta_t: c.theta_t_deg.to_radians(),
                d_t: c.d_t,
                clearance_cap: c.clearance_cap,
            },
        }
    }
}
