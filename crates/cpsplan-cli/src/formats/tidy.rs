//! Numbers as people read them in the report's files: every float rounded to
//! 12 significant digits, so that the last-bit noise of cell arithmetic
//! (`5.050000000000001`, `444.55000000000007`) does not reach `episode.json`,
//! `summary.json`, the CSV files or `plan`'s output. Twelve digits keep a
//! micrometre on a thousand kilometres. Files that are read back to continue
//! work (experiment records and plans, campaign state) keep every bit.

use std::io;

use serde::Serialize;
use serde_json::ser::{Formatter, PrettyFormatter};

/// Significant digits kept.
pub const DIGITS: usize = 12;

/// `v` rounded to [`DIGITS`] significant digits (non-finite values as they are).
pub fn tidy(v: f64) -> f64 {
    if !v.is_finite() || v == 0.0 {
        return v;
    }
    format!("{v:.prec$e}", prec = DIGITS - 1)
        .parse()
        .unwrap_or(v)
}

/// [`tidy`] of an optional value.
pub fn tidy_opt(v: Option<f64>) -> Option<f64> {
    v.map(tidy)
}

/// `value` as pretty JSON with every float [`tidy`].
pub fn to_json_tidy<T: Serialize + ?Sized>(value: &T) -> serde_json::Result<Vec<u8>> {
    let mut out = Vec::new();
    let mut ser = serde_json::Serializer::with_formatter(&mut out, Tidy(PrettyFormatter::new()));
    value.serialize(&mut ser)?;
    Ok(out)
}

/// A pretty formatter writing floats [`tidy`].
struct Tidy<'a>(PrettyFormatter<'a>);

impl Formatter for Tidy<'_> {
    fn write_f64<W: ?Sized + io::Write>(&mut self, w: &mut W, v: f64) -> io::Result<()> {
        self.0.write_f64(w, tidy(v))
    }
    fn write_f32<W: ?Sized + io::Write>(&mut self, w: &mut W, v: f32) -> io::Result<()> {
        self.0.write_f64(w, tidy(f64::from(v)))
    }
    fn begin_array<W: ?Sized + io::Write>(&mut self, w: &mut W) -> io::Result<()> {
        self.0.begin_array(w)
    }
    fn end_array<W: ?Sized + io::Write>(&mut self, w: &mut W) -> io::Result<()> {
        self.0.end_array(w)
    }
    fn begin_array_value<W: ?Sized + io::Write>(
        &mut self,
        w: &mut W,
        first: bool,
    ) -> io::Result<()> {
        self.0.begin_array_value(w, first)
    }
    fn end_array_value<W: ?Sized + io::Write>(&mut self, w: &mut W) -> io::Result<()> {
        self.0.end_array_value(w)
    }
    fn begin_object<W: ?Sized + io::Write>(&mut self, w: &mut W) -> io::Result<()> {
        self.0.begin_object(w)
    }
    fn end_object<W: ?Sized + io::Write>(&mut self, w: &mut W) -> io::Result<()> {
        self.0.end_object(w)
    }
    fn begin_object_key<W: ?Sized + io::Write>(
        &mut self,
        w: &mut W,
        first: bool,
    ) -> io::Result<()> {
        self.0.begin_object_key(w, first)
    }
    fn begin_object_value<W: ?Sized + io::Write>(&mut self, w: &mut W) -> io::Result<()> {
        self.0.begin_object_value(w)
    }
    fn end_object_value<W: ?Sized + io::Write>(&mut self, w: &mut W) -> io::Result<()> {
        self.0.end_object_value(w)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cell_arithmetic_noise_is_gone_and_real_digits_stay() {
        assert_eq!(tidy(5.050000000000001), 5.05);
        assert_eq!(tidy(444.55000000000007), 444.55);
        assert_eq!(tidy(0.1 + 0.2), 0.3);
        assert_eq!(tidy(193_852.700_000_000_03), 193_852.7);
        assert_eq!(tidy(0.118_245_220_185_340_84), 0.118_245_220_185);
        assert_eq!(tidy(-2.5e-9), -2.5e-9);
        assert_eq!(tidy(0.0), 0.0);
        assert!(tidy(f64::NAN).is_nan());
        assert_eq!(tidy(f64::INFINITY), f64::INFINITY);
    }

    #[test]
    fn json_is_pretty_and_tidy() {
        #[derive(Serialize)]
        struct P {
            x: f64,
            list: Vec<f64>,
            n: u32,
        }
        let text = to_json_tidy(&P {
            x: 27.650000000000002,
            list: vec![0.1 + 0.2, 1.0],
            n: 3,
        })
        .unwrap();
        let text = String::from_utf8(text).unwrap();
        assert_eq!(
            text,
            "{\n  \"x\": 27.65,\n  \"list\": [\n    0.3,\n    1.0\n  ],\n  \"n\": 3\n}"
        );
    }
}
