//! The rules every reader follows as it hands over points: the point limit,
//! the policy for non-finite coordinates, capped preallocation, progress
//! reports and the split into scans.

use super::{Cloud, CloudFormat, CloudProblem, CloudReadOptions, CloudScan};

/// Points between two progress reports.
const PROGRESS_EVERY: u64 = 1 << 16;

/// Most points preallocated from a header's count before any is read.
const MAX_PREALLOCATED: u64 = 1 << 20;

/// Gathers the points of one file.
pub(crate) struct Collector<'a> {
    options: &'a CloudReadOptions,
    progress: &'a mut dyn FnMut(u64, u64),
    /// Points the file claims (for progress reports).
    claimed: u64,
    /// Points of the file seen so far, kept or not.
    seen: u64,
    points: Vec<[f64; 3]>,
    scans: Vec<CloudScan>,
    scan_start: usize,
    flagged: u64,
    non_finite: u64,
    notes: Vec<String>,
}

impl<'a> Collector<'a> {
    /// A collector for a file that claims `claimed` points; refuses a claim
    /// beyond `options.max_points` before anything is allocated.
    pub(crate) fn new(
        options: &'a CloudReadOptions,
        progress: &'a mut dyn FnMut(u64, u64),
        claimed: u64,
    ) -> Result<Self, CloudProblem> {
        check_claim(claimed, options)?;
        let capacity = claimed.min(options.max_points).min(MAX_PREALLOCATED) as usize;
        Ok(Self {
            options,
            progress,
            claimed,
            seen: 0,
            points: Vec::with_capacity(capacity),
            scans: Vec::new(),
            scan_start: 0,
            flagged: 0,
            non_finite: 0,
            notes: Vec::new(),
        })
    }

    /// Takes the file's next point: kept if finite; a non-finite one is an
    /// error, or with `drop_invalid` counted and skipped.
    pub(crate) fn push(&mut self, p: [f64; 3]) -> Result<(), CloudProblem> {
        let index = self.advance()?;
        if p.iter().all(|c| c.is_finite()) {
            self.points.push(p);
        } else if self.options.drop_invalid {
            self.non_finite += 1;
        } else {
            let kind = if p.iter().any(|c| c.is_nan()) {
                "NaN"
            } else {
                "infinite"
            };
            return Err(CloudProblem::NonFinite { index, kind });
        }
        Ok(())
    }

    /// Counts a point the file itself flags as invalid (and drops it).
    pub(crate) fn push_flagged(&mut self) -> Result<(), CloudProblem> {
        self.advance()?;
        self.flagged += 1;
        Ok(())
    }

    /// Points of the file seen so far.
    pub(crate) fn seen(&self) -> u64 {
        self.seen
    }

    /// Ends the current scan (the points taken since the last call).
    pub(crate) fn end_scan(&mut self, origin: Option<[f64; 3]>) {
        let end = self.points.len();
        self.scans.push(CloudScan {
            points: self.scan_start..end,
            origin,
        });
        self.scan_start = end;
    }

    /// Adds a note for the user.
    pub(crate) fn note(&mut self, note: String) {
        self.notes.push(note);
    }

    /// The cloud; an error if it holds no point. Points after the last
    /// [`Collector::end_scan`] make a scan of their own without origin.
    pub(crate) fn finish(mut self, format: CloudFormat) -> Result<Cloud, CloudProblem> {
        if self.seen == 0 {
            return Err(CloudProblem::Empty);
        }
        if self.points.is_empty() {
            return Err(CloudProblem::NoValidPoints(self.seen));
        }
        if self.scan_start < self.points.len() || self.scans.is_empty() {
            self.end_scan(None);
        }
        if !self.seen.is_multiple_of(PROGRESS_EVERY) {
            (self.progress)(self.seen, self.claimed.max(self.seen));
        }
        if self.flagged > 0 {
            self.notes.push(format!(
                "{} flagged invalid by the file {} dropped",
                count(self.flagged, "point", "points"),
                if self.flagged == 1 { "was" } else { "were" }
            ));
        }
        if self.non_finite > 0 {
            self.notes.push(format!(
                "{} with a NaN or infinite coordinate {} dropped (--drop-invalid)",
                count(self.non_finite, "point", "points"),
                if self.non_finite == 1 { "was" } else { "were" }
            ));
        }
        self.points.shrink_to_fit();
        Ok(Cloud {
            points: self.points,
            scans: self.scans,
            format,
            points_in_file: self.seen,
            points_dropped: self.flagged + self.non_finite,
            notes: self.notes,
            metres_per_unit: [1.0, 1.0],
            crs: None,
        })
    }

    /// Counts one more point of the file, checks the limit, reports progress;
    /// the point's index.
    fn advance(&mut self) -> Result<u64, CloudProblem> {
        let index = self.seen;
        if index >= self.options.max_points {
            return Err(CloudProblem::TooManyPoints {
                points: index + 1,
                limit: self.options.max_points,
            });
        }
        self.seen += 1;
        if self.seen.is_multiple_of(PROGRESS_EVERY) {
            (self.progress)(self.seen, self.claimed.max(self.seen));
        }
        Ok(index)
    }
}

/// Refuses a file that claims more than `options.max_points` points.
pub(crate) fn check_claim(claimed: u64, options: &CloudReadOptions) -> Result<(), CloudProblem> {
    if claimed > options.max_points {
        return Err(CloudProblem::TooManyPoints {
            points: claimed,
            limit: options.max_points,
        });
    }
    Ok(())
}

/// `n` with its noun: `1 point`, `2 points`.
fn count(n: u64, one: &str, many: &str) -> String {
    format!("{n} {}", if n == 1 { one } else { many })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn options(drop_invalid: bool, max_points: u64) -> CloudReadOptions {
        CloudReadOptions {
            drop_invalid,
            max_points,
            ..CloudReadOptions::default()
        }
    }

    #[test]
    fn non_finite_points_are_refused_by_default_and_counted_when_dropped() {
        let strict = options(false, 10);
        let mut progress = |_, _| {};
        let mut c = Collector::new(&strict, &mut progress, 3).unwrap();
        c.push([1.0, 2.0, 3.0]).unwrap();
        let e = c.push([1.0, f64::NAN, 3.0]).unwrap_err();
        assert_eq!(
            e.to_string(),
            "point 1 has a NaN coordinate (pass --drop-invalid to skip such points)"
        );

        let lenient = options(true, 10);
        let mut c = Collector::new(&lenient, &mut progress, 3).unwrap();
        c.push([1.0, 2.0, 3.0]).unwrap();
        c.push([f64::INFINITY, 2.0, 3.0]).unwrap();
        c.push_flagged().unwrap();
        let cloud = c.finish(CloudFormat::Ply).unwrap();
        assert_eq!(cloud.points, vec![[1.0, 2.0, 3.0]]);
        assert_eq!(cloud.points_in_file, 3);
        assert_eq!(cloud.points_dropped, 2);
        assert_eq!(cloud.notes.len(), 2);
        assert_eq!(
            cloud.scans,
            vec![CloudScan {
                points: 0..1,
                origin: None
            }]
        );
    }

    #[test]
    fn the_point_limit_holds_for_claims_and_for_points() {
        let o = options(false, 2);
        let mut progress = |_, _| {};
        assert!(matches!(
            Collector::new(&o, &mut progress, 3),
            Err(CloudProblem::TooManyPoints {
                points: 3,
                limit: 2
            })
        ));
        let mut c = Collector::new(&o, &mut progress, 0).unwrap();
        c.push([0.0; 3]).unwrap();
        c.push([0.0; 3]).unwrap();
        let e = c.push([0.0; 3]).unwrap_err();
        assert!(e.to_string().contains("limits.max_cloud_points"), "{e}");
    }

    #[test]
    fn huge_claims_preallocate_little() {
        let o = options(false, u64::MAX);
        let mut progress = |_, _| {};
        let c = Collector::new(&o, &mut progress, u64::MAX).unwrap();
        assert!(c.points.capacity() <= MAX_PREALLOCATED as usize);
    }

    #[test]
    fn empty_and_all_invalid_clouds_are_errors() {
        let o = options(true, 10);
        let mut progress = |_, _| {};
        let c = Collector::new(&o, &mut progress, 0).unwrap();
        assert!(matches!(
            c.finish(CloudFormat::Pcd),
            Err(CloudProblem::Empty)
        ));
        let mut c = Collector::new(&o, &mut progress, 1).unwrap();
        c.push([f64::NAN; 3]).unwrap();
        assert!(matches!(
            c.finish(CloudFormat::Pcd),
            Err(CloudProblem::NoValidPoints(1))
        ));
    }

    #[test]
    fn scans_split_the_points_and_progress_is_reported() {
        let o = options(false, u64::MAX);
        let mut reports = Vec::new();
        let mut progress = |done, total| reports.push((done, total));
        let mut c = Collector::new(&o, &mut progress, 70_000).unwrap();
        for i in 0..70_000 {
            c.push([i as f64, 0.0, 0.0]).unwrap();
            if i == 99 {
                c.end_scan(Some([1.0, 2.0, 3.0]));
            }
        }
        c.end_scan(None);
        let cloud = c.finish(CloudFormat::E57).unwrap();
        assert_eq!(
            cloud.scans,
            vec![
                CloudScan {
                    points: 0..100,
                    origin: Some([1.0, 2.0, 3.0])
                },
                CloudScan {
                    points: 100..70_000,
                    origin: None
                },
            ]
        );
        assert_eq!(reports, vec![(65_536, 70_000), (70_000, 70_000)]);
    }
}
