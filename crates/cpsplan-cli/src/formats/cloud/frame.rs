//! The frame of a map made from a point cloud (`grid --cloud`), kept beside the
//! map as `MAP.frame.json`: how the map's metres go back to the cloud's own
//! coordinates (its length units, the `--transform` applied, the ground the
//! heights were measured from) and the cloud's coordinate reference system (its
//! LAS `LASF_Projection` records). `explore --map MAP.yaml --cloud-out` writes
//! the registered model in that frame, so the model lies on its source cloud in
//! any viewer.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use cpsplan::world::projection::{Ground, PlanarTransform};
use cpsplan::GridGeometry;
use serde::{Deserialize, Serialize};

/// The format tag of a frame file.
pub const FRAME_FORMAT: &str = "cpsplan-source-frame/1";

/// How a cloud-derived map's metres go back to its source cloud.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SourceFrame {
    /// [`FRAME_FORMAT`].
    pub format: String,
    /// The cloud the map was made from, as `grid` was given it.
    pub source: String,
    /// Metres per unit of the source's x and y, and of its heights.
    pub metres_per_unit: [f64; 2],
    /// The `--transform` applied before projecting, metres and radians:
    /// map = R(yaw) · source + (tx, ty).
    pub transform: [f64; 3],
    /// The ground the map's heights stand on, in the (transformed) map frame.
    pub ground: FrameGround,
    /// The source's coordinate reference system, when it had one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub crs: Option<SourceCrs>,
}

/// The ground of a [`SourceFrame`], metres.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum FrameGround {
    /// Heights were absolute: the model's floor is the source's z = 0.
    Flat,
    /// `z = a·(x − x0) + b·(y − y0) + c`.
    Plane {
        /// Slope along x.
        a: f64,
        /// Slope along y.
        b: f64,
        /// Height at `at`.
        c: f64,
        /// `(x0, y0)`.
        at: [f64; 2],
    },
    /// A height per cell of a grid (row-major, `null` where no point was near).
    Cells {
        /// Lower-left corner of the grid.
        origin: [f64; 2],
        /// Cell side.
        resolution: f64,
        /// Cells along x.
        width: usize,
        /// Cells along y.
        height: usize,
        /// The heights, millimetre-rounded.
        heights: Vec<Option<f64>>,
    },
}

/// A LAS file's coordinate reference system: its `LASF_Projection` records.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SourceCrs {
    /// Whether the file flagged its CRS as WKT (global encoding bit 4).
    pub wkt: bool,
    /// The records, in the file's order.
    pub records: Vec<CrsRecord>,
}

/// One `LASF_Projection` record.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CrsRecord {
    /// Its record id (34735–34737 GeoTIFF keys, 2111–2112 WKT).
    pub record_id: u16,
    /// Its description.
    pub description: String,
    /// Its bytes, in hexadecimal.
    pub data_hex: String,
}

/// The LAS user id of coordinate-system records.
pub const CRS_USER_ID: &str = "LASF_Projection";

impl SourceCrs {
    /// The coordinate-system records among `vlrs` (`None` when there are none).
    pub fn of<'a>(vlrs: impl IntoIterator<Item = &'a ::las::Vlr>, wkt: bool) -> Option<Self> {
        let records: Vec<CrsRecord> = vlrs
            .into_iter()
            .filter(|v| v.user_id == CRS_USER_ID && v.data.len() <= usize::from(u16::MAX))
            .map(|v| CrsRecord {
                record_id: v.record_id,
                description: v.description.clone(),
                data_hex: v.data.iter().map(|b| format!("{b:02x}")).collect(),
            })
            .collect();
        (!records.is_empty()).then_some(Self { wkt, records })
    }

    /// The records as LAS VLRs.
    pub fn vlrs(&self) -> Result<Vec<::las::Vlr>> {
        self.records
            .iter()
            .map(|r| {
                let hex = r.data_hex.as_bytes();
                if hex.len() % 2 != 0 {
                    bail!("CRS record {}: odd hexadecimal", r.record_id);
                }
                let data = hex
                    .chunks(2)
                    .map(|pair| {
                        std::str::from_utf8(pair)
                            .ok()
                            .and_then(|s| u8::from_str_radix(s, 16).ok())
                    })
                    .collect::<Option<Vec<u8>>>()
                    .with_context(|| format!("CRS record {}: not hexadecimal", r.record_id))?;
                Ok(::las::Vlr {
                    user_id: CRS_USER_ID.to_string(),
                    record_id: r.record_id,
                    description: r.description.clone(),
                    data,
                })
            })
            .collect()
    }
}

impl FrameGround {
    /// The frame's copy of an estimated ground on `geometry`'s cells.
    pub fn of(ground: &Ground, geometry: &GridGeometry) -> Self {
        match ground {
            Ground::Flat => FrameGround::Flat,
            Ground::Plane { a, b, c, at, .. } => FrameGround::Plane {
                a: *a,
                b: *b,
                c: *c,
                at: [at.x, at.y],
            },
            Ground::Cells(h) => FrameGround::Cells {
                origin: [geometry.origin.x, geometry.origin.y],
                resolution: geometry.resolution,
                width: geometry.width,
                height: geometry.height,
                heights: h
                    .iter()
                    .map(|&z| z.is_finite().then(|| (z * 1000.0).round() / 1000.0))
                    .collect(),
            },
        }
    }

    /// The ground's height under map point `(x, y)`: for cells, the nearest
    /// cell's within the grid that has one, else the mean of all.
    pub fn height(&self, x: f64, y: f64) -> f64 {
        self.height_near(x, y).unwrap_or_else(|| self.mean())
    }

    /// The mean height of the cells that have one (0 without cells): where a
    /// point has no cell with a height near it.
    pub fn mean(&self) -> f64 {
        let FrameGround::Cells { heights, .. } = self else {
            return 0.0;
        };
        let (sum, n) = heights
            .iter()
            .flatten()
            .fold((0.0, 0usize), |(s, n), h| (s + h, n + 1));
        if n == 0 {
            0.0
        } else {
            sum / n as f64
        }
    }

    /// The ground's height under `(x, y)`; for cells, the lowest within a few
    /// rings of the nearest cell, `None` when none has a height.
    fn height_near(&self, x: f64, y: f64) -> Option<f64> {
        match self {
            FrameGround::Flat => Some(0.0),
            FrameGround::Plane { a, b, c, at } => Some(a * (x - at[0]) + b * (y - at[1]) + c),
            FrameGround::Cells {
                origin,
                resolution,
                width,
                height,
                heights,
            } => {
                let cx = ((x - origin[0]) / resolution).floor();
                let cy = ((y - origin[1]) / resolution).floor();
                let clamp = |v: f64, n: usize| v.clamp(0.0, n.saturating_sub(1) as f64) as usize;
                let (cx, cy) = (clamp(cx, *width), clamp(cy, *height));
                // The nearest cell with a height, ring by ring (a few rings).
                for ring in 0..=8usize {
                    let mut best: Option<f64> = None;
                    let (x0, x1) = (cx.saturating_sub(ring), (cx + ring).min(width - 1));
                    let (y0, y1) = (cy.saturating_sub(ring), (cy + ring).min(height - 1));
                    for j in y0..=y1 {
                        for i in x0..=x1 {
                            if let Some(Some(h)) = heights.get(j * width + i) {
                                best = Some(best.map_or(*h, |b: f64| b.min(*h)));
                            }
                        }
                    }
                    if best.is_some() {
                        return best;
                    }
                }
                None
            }
        }
    }
}

impl SourceFrame {
    /// Where map point `p` (metres, `z` above the ground) lies in the source
    /// cloud's own coordinates and units.
    pub fn to_source(&self, p: [f64; 3]) -> [f64; 3] {
        self.placer()(p)
    }

    /// [`Self::to_source`] for many points: the ground's mean (for points
    /// with no height near them) taken once.
    pub fn placer(&self) -> impl Fn([f64; 3]) -> [f64; 3] + '_ {
        let mean = self.ground.mean();
        let [tx, ty, yaw] = self.transform;
        let transform = PlanarTransform { tx, ty, yaw };
        let [h, v] = self.metres_per_unit;
        move |p| {
            let ground = self.ground.height_near(p[0], p[1]).unwrap_or(mean);
            let back = transform.unapply([p[0], p[1], p[2] + ground]);
            [back[0] / h, back[1] / h, back[2] / v]
        }
    }

    /// Whether map coordinates are the source's own (metres, no transform, no
    /// ground, no CRS).
    pub fn is_identity(&self) -> bool {
        self.metres_per_unit == [1.0, 1.0]
            && self.transform == [0.0; 3]
            && self.ground == FrameGround::Flat
            && self.crs.is_none()
    }

    /// The frame file beside the map `yaml` (`MAP.yaml` → `MAP.frame.json`).
    pub fn path_beside(yaml: &Path) -> PathBuf {
        yaml.with_extension("frame.json")
    }

    /// The frame file beside the map `yaml`, if there is one; an unreadable or
    /// malformed one is an error naming it.
    pub fn load_beside(yaml: &Path) -> Result<Option<Self>> {
        let path = Self::path_beside(yaml);
        if !path.is_file() {
            return Ok(None);
        }
        let text = std::fs::read_to_string(&path)
            .with_context(|| format!("cannot read {}", path.display()))?;
        let frame: SourceFrame = serde_json::from_str(&text)
            .with_context(|| format!("{}: not a cpsplan source frame", path.display()))?;
        if frame.format != FRAME_FORMAT {
            bail!(
                "{}: format {:?}, this cpsplan reads {FRAME_FORMAT:?}",
                path.display(),
                frame.format
            );
        }
        let finite = frame
            .metres_per_unit
            .iter()
            .all(|f| f.is_finite() && *f > 0.0)
            && frame.transform.iter().all(|t| t.is_finite());
        if !finite {
            bail!("{}: units or transform out of range", path.display());
        }
        if let FrameGround::Cells {
            width,
            height,
            heights,
            resolution,
            ..
        } = &frame.ground
        {
            if width.checked_mul(*height) != Some(heights.len())
                || *width == 0
                || !(resolution.is_finite() && *resolution > 0.0)
            {
                bail!(
                    "{}: the ground's cells do not match its size",
                    path.display()
                );
            }
        }
        Ok(Some(frame))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame(ground: FrameGround) -> SourceFrame {
        SourceFrame {
            format: FRAME_FORMAT.into(),
            source: "x.laz".into(),
            metres_per_unit: [0.3048, 0.3048],
            transform: [10.0, -5.0, 0.5],
            ground,
            crs: None,
        }
    }

    #[test]
    fn a_map_point_goes_back_to_the_source_units_and_ground() {
        let f = frame(FrameGround::Plane {
            a: 0.01,
            b: 0.0,
            c: -1.25,
            at: [0.0, 0.0],
        });
        // The source point (100 ft, 50 ft) at ground + 2 m.
        let src_m = [100.0 * 0.3048, 50.0 * 0.3048, 0.0];
        let t = PlanarTransform {
            tx: 10.0,
            ty: -5.0,
            yaw: 0.5,
        };
        let map = t.apply(src_m);
        let ground = 0.01 * map[0] - 1.25;
        let back = f.to_source([map[0], map[1], 2.0]);
        assert!(
            (back[0] - 100.0).abs() < 1e-9 && (back[1] - 50.0).abs() < 1e-9,
            "{back:?}"
        );
        assert!((back[2] - (ground + 2.0) / 0.3048).abs() < 1e-9);
    }

    #[test]
    fn cells_without_a_height_take_the_nearest() {
        let g = FrameGround::Cells {
            origin: [0.0, 0.0],
            resolution: 1.0,
            width: 3,
            height: 1,
            heights: vec![Some(-2.0), None, Some(5.0)],
        };
        assert_eq!(g.height(0.5, 0.5), -2.0);
        assert_eq!(g.height(1.5, 0.5), -2.0);
        assert_eq!(g.height(2.5, 0.2), 5.0);
        assert_eq!(g.height(-40.0, 9.0), -2.0);
    }

    #[test]
    fn crs_records_round_trip_through_hex() {
        let vlr = ::las::Vlr {
            user_id: CRS_USER_ID.into(),
            record_id: 34735,
            description: "GeoTIFF GeoKeyDirectoryTag".into(),
            data: vec![1, 0, 1, 0, 0, 255, 16],
        };
        let other = ::las::Vlr {
            user_id: "LASF_Spec".into(),
            record_id: 4,
            description: String::new(),
            data: vec![9; 4],
        };
        let crs = SourceCrs::of([&vlr, &other], false).unwrap();
        assert_eq!(crs.records.len(), 1);
        assert_eq!(crs.vlrs().unwrap(), vec![vlr]);
        assert!(SourceCrs::of([], false).is_none());
    }
}
