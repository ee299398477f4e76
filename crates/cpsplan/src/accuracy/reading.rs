//! One total-station reading as the instrument records it: at a station (a
//! set-up of the parent), to a point (a child's marker, a target or a control
//! point), the slope distance, the horizontal direction and the zenith angle.
//!
//! In: a reading, or a [`Model`]'s observation. Out: the other.
//!
//! Conventions (docs/USER-GUIDE.md "Readings"):
//! - the horizontal direction `Hz` is read **clockwise** from the instrument's
//!   zero, as every total station reads it; the model's direction `r` turns
//!   counter-clockwise (`r = atan2(Δy, Δx) − ω`), so `r = −Hz` (mod 2π), and the
//!   circle's orientation `ω` takes up where the zero points;
//! - the zenith angle is 0 straight up and π/2 level, one face (face I): a
//!   reading in face II is reduced to face I before it is given;
//! - the planar model keeps the horizontal distance `s·sin ζ` and the
//!   direction; the 3D model the slope distance, the direction and the zenith.

use std::f64::consts::{FRAC_PI_2, PI, TAU};

use nalgebra::DVector;

use super::model::Model;

/// One reading of the instrument.
#[derive(Debug, Clone, PartialEq)]
pub struct Reading {
    /// The station (set-up) it was taken at.
    pub station: String,
    /// The point it was taken to.
    pub point: String,
    /// Slope distance, metres (> 0).
    pub slope_distance_m: f64,
    /// Horizontal direction, clockwise, radians in `[0, 2π)`.
    pub hz_rad: f64,
    /// Zenith angle, radians in `(0, π)`.
    pub zenith_rad: f64,
}

/// The longest station or point name.
pub const MAX_NAME: usize = 64;

impl Reading {
    /// Whether `name` may name a station or a point: 1 to [`MAX_NAME`]
    /// letters, digits, `.`, `_`, `-` or `:` (what survey software exchanges).
    pub fn valid_name(name: &str) -> bool {
        !name.is_empty()
            && name.len() <= MAX_NAME
            && name
                .chars()
                .all(|ch| ch.is_ascii_alphanumeric() || "._-:".contains(ch))
    }

    /// The reading of `model`'s observation `z` (planar: `[d, r]`, taken level;
    /// 3D: `[s, r, ζ]`) from `station` to `point`.
    pub fn from_observation(station: &str, point: &str, model: &Model, z: &[f64]) -> Self {
        let zenith = if model.three_d() { z[2] } else { FRAC_PI_2 };
        Self {
            station: station.to_string(),
            point: point.to_string(),
            slope_distance_m: z[0],
            hz_rad: (-z[1]).rem_euclid(TAU),
            zenith_rad: zenith,
        }
    }

    /// `model`'s observation of this reading, its direction in `(−π, π]`.
    pub fn observation(&self, model: &Model) -> DVector<f64> {
        let mut r = (-self.hz_rad).rem_euclid(TAU);
        if r > PI {
            r -= TAU;
        }
        if model.three_d() {
            DVector::from_vec(vec![self.slope_distance_m, r, self.zenith_rad])
        } else {
            let horizontal = self.slope_distance_m * self.zenith_rad.sin();
            DVector::from_vec(vec![horizontal, r])
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accuracy::model::tests::models;
    use crate::geom::Point;
    use proptest::prelude::*;

    /// The angular distance of two directions.
    fn apart(a: f64, b: f64) -> f64 {
        let d = (a - b).rem_euclid(TAU);
        d.min(TAU - d)
    }

    proptest! {
        /// A reading of an observation gives the observation back, and the
        /// point it names lies where the model puts it.
        #[test]
        fn observations_round_trip(
            sx in -50.0f64..50.0, sy in -50.0f64..50.0, omega in -7.0f64..7.0,
            cx in -50.0f64..50.0, cy in -50.0f64..50.0,
        ) {
            prop_assume!((cx - sx).hypot(cy - sy) > 0.5);
            for m in models() {
                let s = m.station(Point::new(sx, sy), omega);
                let c = m.point(Point::new(cx, cy));
                let z = m.observe(s.as_slice(), c.as_slice());
                let reading = Reading::from_observation("S1", "C1.1", &m, z.as_slice());
                prop_assert!((0.0..TAU).contains(&reading.hz_rad));
                let back = reading.observation(&m);
                prop_assert!((back[0] - z[0]).abs() < 1e-9);
                prop_assert!(apart(back[1], z[1]) < 1e-12);
                let point = m.forward(s.as_slice(), back.as_slice());
                prop_assert!((point - &c).abs().max() < 1e-9);
            }
        }
    }

    #[test]
    fn names_are_what_survey_software_exchanges() {
        for ok in ["S0001", "C1.0003", "GNSS-1", "t_2:a"] {
            assert!(Reading::valid_name(ok), "{ok}");
        }
        for bad in ["", "C 1", "a,b", "é", &"x".repeat(MAX_NAME + 1)] {
            assert!(!Reading::valid_name(bad), "{bad}");
        }
    }

    #[test]
    fn hz_is_clockwise() {
        let m = models()[0];
        let s = m.station(Point::new(0.0, 0.0), 0.0);
        // A point to the north (a quarter turn counter-clockwise from the
        // circle's zero along +x) reads a quarter turn less clockwise: 3π/2.
        let z = m.observe(s.as_slice(), m.point(Point::new(0.0, 10.0)).as_slice());
        let reading = Reading::from_observation("S1", "T1", &m, z.as_slice());
        assert!((reading.hz_rad - 1.5 * PI).abs() < 1e-12);
        assert!((reading.zenith_rad - FRAC_PI_2).abs() < 1e-15);
    }

    #[test]
    fn a_planar_reading_keeps_the_horizontal_distance() {
        let reading = Reading {
            station: "S1".into(),
            point: "C2.4".into(),
            slope_distance_m: 10.0,
            hz_rad: 0.5,
            zenith_rad: FRAC_PI_2 - 0.1,
        };
        let z = reading.observation(&models()[0]);
        assert!((z[0] - 10.0 * (FRAC_PI_2 - 0.1).sin()).abs() < 1e-12);
        assert!((z[1] + 0.5).abs() < 1e-12);
        let z3 = reading.observation(&models()[1]);
        assert_eq!((z3[0], z3[2]), (10.0, FRAC_PI_2 - 0.1));
    }
}
