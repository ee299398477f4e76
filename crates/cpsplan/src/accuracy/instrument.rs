//! The instrument that measures the CPS links: a total station (or a scanner that
//! finds the markers in its scans) measuring, to each child's marker, a distance
//! and a horizontal direction, and in 3D mode a zenith angle (paper Table I).
//!
//! In: the configuration's `[instrument]`. Out: an [`Instrument`] with the
//! standard deviation of each kind of observation.

use crate::config::{InstrumentConfig, InstrumentModel};

/// One arc second in radians.
pub const ARCSEC: f64 = std::f64::consts::PI / (180.0 * 3600.0);

/// An instrument's accuracy and range, resolved from a preset and the
/// configuration's overrides.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Instrument {
    /// The preset's name.
    pub name: &'static str,
    /// What it is and where its figures come from.
    pub description: &'static str,
    /// Distance accuracy, constant part, metres (σ = a + b·d).
    pub distance_sigma: f64,
    /// Distance accuracy, part proportional to the distance (b; 2 ppm = 2e-6).
    pub distance_ppm: f64,
    /// Accuracy of one direction (horizontal, and zenith in 3D), radians.
    pub angle_sigma: f64,
    /// Shortest measurable distance, metres.
    pub min_range: f64,
    /// Longest measurable distance, metres.
    pub max_range: f64,
    /// Whether slope distances and zenith angles are measured (3D positions).
    pub three_d: bool,
    /// Height of the instrument's axis over the ground, metres (3D mode).
    pub instrument_height: f64,
    /// Height of the markers over the ground, metres (3D mode).
    pub marker_height: f64,
}

impl Instrument {
    /// The figures of a preset, as its maker publishes them (prism or marker
    /// mode, standard measurement), with the configuration's defaults for the
    /// rest.
    pub fn preset(model: InstrumentModel) -> Self {
        let (min, max) = model.range_m();
        let (name, description, mm, ppm, arcsec) = match model {
            InstrumentModel::Gpt9005a => (
                "gpt-9005a",
                "TOPCON GPT-9005A, the paper's total station (Table I: 2 mm + 2 ppm, 1\u{2033}, 1.3-3,000 m)",
                2.0,
                2.0,
                1.0,
            ),
            InstrumentModel::Ts16 => (
                "ts16",
                "Leica Viva TS16, 1\u{2033} model (Leica TS16 data sheet: angle 1\u{2033}, prism 1 mm + 1.5 ppm, 1.5-3,500 m)",
                1.0,
                1.5,
                1.0,
            ),
            InstrumentModel::Ts60 => (
                "ts60",
                "Leica Nova TS60 (Leica TS60 data sheet: angle 0.5\u{2033}, prism 0.6 mm + 1 ppm, 1.5-3,500 m)",
                0.6,
                1.0,
                0.5,
            ),
            InstrumentModel::Ms05axii => (
                "ms05axii",
                "Topcon MS05AXII (Topcon MS AXII brochure: angle 0.5\u{2033}, prism 0.8 mm + 1 ppm, 1.3-3,500 m)",
                0.8,
                1.0,
                0.5,
            ),
            InstrumentModel::FocusS350 => (
                "focus-s350",
                "FARO Focus S 350 laser scanner (FARO Focus S tech sheet: ranging error 1 mm, angular accuracy 19\u{2033}, 0.6-350 m)",
                1.0,
                0.0,
                19.0,
            ),
        };
        let d = InstrumentConfig::default();
        Self {
            name,
            description,
            distance_sigma: mm * 1e-3,
            distance_ppm: ppm * 1e-6,
            angle_sigma: arcsec * ARCSEC,
            min_range: min,
            max_range: max,
            three_d: d.three_d,
            instrument_height: d.instrument_height,
            marker_height: d.marker_height,
        }
    }

    /// The instrument of a configuration: its preset with every figure the
    /// configuration gives instead.
    pub fn from_config(c: &InstrumentConfig) -> Self {
        let mut i = Self::preset(c.model);
        if let Some(mm) = c.distance_sigma_mm {
            i.distance_sigma = mm * 1e-3;
        }
        if let Some(ppm) = c.distance_ppm {
            i.distance_ppm = ppm * 1e-6;
        }
        if let Some(s) = c.angle_sigma_arcsec {
            i.angle_sigma = s * ARCSEC;
        }
        if let Some(m) = c.min_range {
            i.min_range = m;
        }
        if let Some(m) = c.max_range {
            i.max_range = m;
        }
        i.three_d = c.three_d;
        i.instrument_height = c.instrument_height;
        i.marker_height = c.marker_height;
        i
    }

    /// Standard deviation of a distance of `d` metres: a + b·d (the makers'
    /// form).
    pub fn distance_sigma_at(&self, d: f64) -> f64 {
        self.distance_sigma + self.distance_ppm * d
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_default_is_table_one() {
        let i = Instrument::from_config(&InstrumentConfig::default());
        assert_eq!(i.name, "gpt-9005a");
        assert!((i.distance_sigma_at(1000.0) - 0.004).abs() < 1e-12);
        assert!((i.angle_sigma / ARCSEC - 1.0).abs() < 1e-12);
        assert_eq!((i.min_range, i.max_range), (1.3, 3000.0));
    }

    #[test]
    fn overrides_replace_the_preset() {
        let c = InstrumentConfig {
            model: InstrumentModel::Ts60,
            angle_sigma_arcsec: Some(2.0),
            ..InstrumentConfig::default()
        };
        let i = Instrument::from_config(&c);
        assert_eq!(i.name, "ts60");
        assert!((i.angle_sigma / ARCSEC - 2.0).abs() < 1e-12);
        assert!((i.distance_sigma - 0.0006).abs() < 1e-15);
        for m in InstrumentModel::ALL {
            assert_eq!(Instrument::preset(m).name, m.name());
        }
    }
}
