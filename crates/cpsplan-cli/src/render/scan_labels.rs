//! The scan numbers of the episode picture. They never overlap: runs of
//! consecutive scans whose markers touch share one label ("14–19"); a label with
//! no free room nearby joins the next consecutive scans that found none either
//! into one range label; what still finds no room is left out and counted.

use super::canvas::{Canvas, Rect};
use super::chrome::Style;
use super::palette;
use super::placer::{draw_label, label_size, Placer};

/// One placed label: scans `first..=last` (from 0).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct ScanLabel {
    /// First scan, from 0.
    pub first: usize,
    /// Last scan, from 0 (`first` for a single scan).
    pub last: usize,
    /// The label's box.
    pub rect: Rect,
    /// "7" or "14–19".
    pub text: String,
    /// The marker (or the run's centre) and radius a leader line starts from, when
    /// the box sits away from it.
    pub leader: Option<((f32, f32), f32)>,
}

/// Every scan label of a picture and what was left out.
#[derive(Debug, Clone, Default, PartialEq)]
pub(crate) struct ScanLabels {
    /// The placed labels, pairwise disjoint.
    pub labels: Vec<ScanLabel>,
    /// Scans without a label.
    pub omitted: usize,
}

impl ScanLabels {
    /// Scans numbered in range labels.
    #[cfg_attr(not(test), allow(dead_code))]
    pub fn in_ranges(&self) -> usize {
        self.labels
            .iter()
            .filter(|l| l.last > l.first)
            .map(|l| l.last - l.first + 1)
            .sum()
    }

    /// The header's note on the labels: "every scan numbered", or how runs are
    /// labelled and how many labels were left out (`elsewhere`: where to find them).
    pub fn note(&self, elsewhere: Option<&str>) -> String {
        let mut parts = Vec::new();
        if let Some(l) = self.labels.iter().find(|l| l.last > l.first) {
            parts.push(format!(
                "{} = scans {} to {}, close together",
                l.text,
                l.first + 1,
                l.last + 1
            ));
        }
        if self.omitted > 0 {
            let mut s = format!(
                "labels of {} scan{} omitted where crowded",
                self.omitted,
                if self.omitted == 1 { "" } else { "s" }
            );
            if let Some(e) = elsewhere {
                s.push_str(&format!(" ({e})"));
            }
            parts.push(s);
        }
        if parts.is_empty() {
            "every scan numbered".to_owned()
        } else {
            parts.join(" \u{b7} ")
        }
    }
}

/// A label to place: scans `first..=last`, markers around `centre` within `radius`.
#[derive(Debug, Clone, Copy)]
struct Unit {
    first: usize,
    last: usize,
    centre: (f32, f32),
    radius: f32,
}

impl Unit {
    fn text(&self) -> String {
        if self.first == self.last {
            (self.first + 1).to_string()
        } else {
            format!("{}\u{2013}{}", self.first + 1, self.last + 1)
        }
    }

    fn count(&self) -> usize {
        self.last - self.first + 1
    }
}

/// The unit of scans `first..=last` with markers of radius `r` at `dots`.
fn unit(dots: &[(f32, f32)], first: usize, last: usize, r: f32) -> Unit {
    let members = &dots[first..=last];
    let n = members.len() as f32;
    let centre = (
        members.iter().map(|d| d.0).sum::<f32>() / n,
        members.iter().map(|d| d.1).sum::<f32>() / n,
    );
    let spread = members
        .iter()
        .map(|d| (d.0 - centre.0).hypot(d.1 - centre.1))
        .fold(0.0f32, f32::max);
    Unit {
        first,
        last,
        centre,
        radius: spread + r,
    }
}

/// Places the numbers of the scans at `dots` (canvas pixels, scan order) with
/// `placer`: the first and the last scan always (their markers have radius
/// `end_radius`), the others (radius `radius`) where there is room. The labels
/// cover no scan marker but their own: every scan's place stays visible.
pub(crate) fn place_scan_labels(
    placer: &mut Placer,
    style: Style,
    dots: &[(f32, f32)],
    radius: f32,
    end_radius: f32,
) -> ScanLabels {
    let mut out = ScanLabels::default();
    placer.protect_markers(dots.len());
    let Some(last) = dots.len().checked_sub(1) else {
        return out;
    };
    let finite = |d: &(f32, f32)| d.0.is_finite() && d.1.is_finite();
    let mut try_place = |out: &mut ScanLabels, u: &Unit, required: bool| -> bool {
        let text = u.text();
        let (w, h) = label_size(&text, style);
        let own = u.first..u.last + 1;
        let r = u.radius + 2.5;
        let placed = placer.place_for(own, u.centre, r, w as f32, h as f32, style, required);
        if let Some((rect, far)) = placed {
            out.labels.push(ScanLabel {
                first: u.first,
                last: u.last,
                rect,
                text,
                leader: far.then_some((u.centre, u.radius + 1.75)),
            });
        }
        placed.is_some()
    };

    // The ends first: they are always numbered.
    for i in [0, last].into_iter().take(if last > 0 { 2 } else { 1 }) {
        if finite(&dots[i]) {
            try_place(&mut out, &unit(dots, i, i, end_radius), true);
        } else {
            out.omitted += 1;
        }
    }

    // Runs of touching markers between the ends, then every run on its own.
    let touching = 2.0 * (radius + 2.5);
    let mut units = Vec::new();
    let mut i = 1;
    while i < last {
        if !finite(&dots[i]) {
            out.omitted += 1;
            i += 1;
            continue;
        }
        let mut j = i;
        while j + 1 < last
            && finite(&dots[j + 1])
            && (dots[j + 1].0 - dots[i].0).hypot(dots[j + 1].1 - dots[i].1) <= touching
        {
            j += 1;
        }
        units.push(unit(dots, i, j, radius));
        i = j + 1;
    }
    let pending: Vec<Unit> = units
        .into_iter()
        .filter(|u| !try_place(&mut out, u, false))
        .collect();

    // Labels without room join the next consecutive ones nearby into a range.
    let (_, label_h) = label_size("0", style);
    let nearby = 5.0 * label_h as f32;
    let mut k = 0;
    while k < pending.len() {
        let start = pending[k];
        let mut end = k;
        while end + 1 < pending.len()
            && pending[end + 1].first == pending[end].last + 1
            && (pending[end + 1].centre.0 - start.centre.0)
                .hypot(pending[end + 1].centre.1 - start.centre.1)
                <= nearby
        {
            end += 1;
        }
        let merged = unit(dots, start.first, pending[end].last, radius);
        if end == k || !try_place(&mut out, &merged, false) {
            out.omitted += merged.count();
        }
        k = end + 1;
    }
    out
}

/// Draws the labels: the first scan's outlined in the start colour, the last's in
/// the end colour, the others grey.
pub(crate) fn draw_scan_labels(
    canvas: &mut Canvas,
    style: Style,
    labels: &ScanLabels,
    last: usize,
) {
    for l in &labels.labels {
        let edge = if l.first == 0 {
            palette::START
        } else if l.last == last && l.first == last {
            palette::END
        } else {
            palette::SWATCH_EDGE
        };
        draw_label(canvas, style, &l.rect, &l.text, edge, l.leader);
    }
}
