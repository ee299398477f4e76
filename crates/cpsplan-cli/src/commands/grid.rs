//! `cpsplan grid`: a 3D point cloud projected to a ROS map_server map.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{anyhow, bail, Result};
use clap::{Args, ValueEnum};
use cpsplan::config::{approx, number};
use cpsplan::world::projection::{
    free_space_pieces, project, BeamOrigin, GroundModel, HeightBand, PlanarTransform, Projection,
    ProjectionParams, FRAGMENTED_SHARE, GAPPY_SHARE,
};
use cpsplan::Config;
use indicatif::{ProgressBar, ProgressStyle};

use super::read_config;
use crate::args::{parse_count, parse_pair, parse_real, parse_transform, parse_triple, parse_unit};
use crate::formats::cloud::{
    read_cloud, Cloud, CloudReadOptions, FrameGround, LengthUnit, SourceFrame, FRAME_FORMAT,
};
use crate::formats::rosmap::save_map_with_notes;
use crate::render::render_map;
use crate::report::write_temp;

/// Options of `cpsplan grid`.
#[derive(Debug, Args)]
pub struct GridArgs {
    /// The point cloud: .las, .laz, .e57, .ply or .pcd.
    #[arg(long, value_name = "FILE")]
    pub cloud: PathBuf,
    /// The map to write: MAP.yaml, with its image MAP.pgm beside it.
    #[arg(long, value_name = "MAP.yaml")]
    pub out: PathBuf,
    /// Cell width of the map, metres.
    #[arg(long, value_name = "M", default_value_t = 0.1, allow_hyphen_values = true, value_parser = parse_real)]
    pub resolution: f64,
    /// Obstacle band by absolute height: lowest z, metres (with --z-max).
    #[arg(long, value_name = "Z", allow_hyphen_values = true, value_parser = parse_real,
          requires = "z_max", conflicts_with_all = ["height_above_ground", "ground"])]
    pub z_min: Option<f64>,
    /// Obstacle band by absolute height: highest z, metres (with --z-min).
    #[arg(long, value_name = "Z", allow_hyphen_values = true, value_parser = parse_real, requires = "z_min")]
    pub z_max: Option<f64>,
    /// Obstacle band by height above the estimated ground, metres: LO,HI.
    #[arg(long, value_name = "LO,HI", allow_hyphen_values = true, value_parser = parse_pair,
          help = "Obstacle band by height above the estimated ground, metres: LO,HI [default: 0.2,2.0 \
                  when no --z-min/--z-max is given]")]
    pub height_above_ground: Option<(f64, f64)>,
    /// How the ground is estimated: none (z = 0), plane (a plane under the
    /// lowest points), lowest (the lowest point within --ground-window).
    #[arg(long, value_enum, default_value = "plane")]
    pub ground: GroundArg,
    /// Half-width of the window of `--ground lowest`, metres.
    #[arg(long, value_name = "M", default_value_t = 2.0, allow_hyphen_values = true, value_parser = parse_real)]
    pub ground_window: f64,
    /// Points in the obstacle band that make a cell occupied.
    #[arg(long, value_name = "N", default_value_t = 1, allow_hyphen_values = true, value_parser = parse_count)]
    pub min_points: usize,
    /// Drop points with fewer than two others within R metres (radius outlier
    /// removal).
    #[arg(long, value_name = "R", allow_hyphen_values = true, value_parser = parse_real)]
    pub outlier_radius: Option<f64>,
    /// Move the cloud into the map frame first: shift TX,TY metres after
    /// rotating by YAW about the cloud's origin (radians; `90deg` for degrees).
    #[arg(long, value_name = "TX,TY,YAW", allow_hyphen_values = true, value_parser = parse_transform)]
    pub transform: Option<(f64, f64, f64)>,
    /// Free space along the beams from the scan origins (E57 poses, a PCD's
    /// VIEWPOINT, or --origin) instead of wherever the ground was seen.
    #[arg(long)]
    pub free_from_scans: bool,
    /// The scanner's centre X,Y,Z in the cloud's frame, for --free-from-scans
    /// (overrides the file's origins).
    #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true, value_parser = parse_triple)]
    pub origin: Option<[f64; 3]>,
    /// Length unit of the file's coordinates, overriding what the file says:
    /// m, ft or us-ft.
    #[arg(long, value_name = "UNIT", value_parser = parse_unit)]
    pub units: Option<LengthUnit>,
    /// Skip points whose coordinates are not finite numbers instead of refusing
    /// the file.
    #[arg(long)]
    pub drop_invalid: bool,
    /// Also draw the map as a PNG picture into this file.
    #[arg(long, value_name = "FILE.png")]
    pub preview: Option<PathBuf>,
    /// TOML file with the limits (`[limits]`; `cpsplan config` prints every key
    /// with its default).
    #[arg(long, value_name = "FILE")]
    pub config: Option<PathBuf>,
    /// Print nothing but errors and warnings.
    #[arg(long, short)]
    pub quiet: bool,
}

/// `--ground` as a command-line value.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum GroundArg {
    /// The ground is z = 0.
    None,
    /// A plane fitted under the lowest points.
    Plane,
    /// The lowest point within --ground-window of each cell.
    Lowest,
}

/// Clouds of at least this many points get a progress bar.
const PROGRESS_POINTS: u64 = 1_000_000;

/// The projection's parameters from the flags.
pub fn params(args: &GridArgs) -> ProjectionParams {
    let band = match (args.z_min, args.z_max, args.height_above_ground) {
        (Some(min), Some(max), _) => HeightBand::Absolute { min, max },
        (_, _, Some((low, high))) => HeightBand::AboveGround { low, high },
        _ => ProjectionParams::default().band,
    };
    let ground = match args.ground {
        GroundArg::None => GroundModel::None,
        GroundArg::Plane => GroundModel::Plane,
        GroundArg::Lowest => GroundModel::Lowest {
            window: args.ground_window,
        },
    };
    let transform = args
        .transform
        .map(|(tx, ty, yaw)| PlanarTransform { tx, ty, yaw })
        .unwrap_or_default();
    ProjectionParams {
        resolution: args.resolution,
        band,
        ground,
        min_points: u32::try_from(args.min_points).unwrap_or(u32::MAX),
        outlier_radius: args.outlier_radius,
        transform,
        free_from_scans: args.free_from_scans,
    }
}

/// The scans with known origins: `--origin` for every scan, else the file's.
fn origins(cloud: &Cloud, origin: Option<[f64; 3]>) -> Vec<BeamOrigin> {
    cloud
        .scans
        .iter()
        .filter_map(|s| {
            origin.or(s.origin).map(|o| BeamOrigin {
                points: s.points.clone(),
                origin: o,
            })
        })
        .collect()
}

fn bar(quiet: bool, total: u64, what: &str) -> ProgressBar {
    if quiet || total < PROGRESS_POINTS {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new(total);
    if let Ok(style) = ProgressStyle::with_template(
        "{spinner} {msg} {bar:30} {human_pos}/{human_len} points {eta}",
    ) {
        bar.set_style(style);
    }
    bar.set_message(what.to_string());
    bar
}

/// Reads the cloud, projects it and writes the map.
pub fn run(args: &GridArgs) -> Result<()> {
    let config = read_config(args.config.as_deref())?.config;
    config.validate()?;
    let params = params(args);
    cpsplan::world::projection::check_params(&params)?;
    if args
        .out
        .extension()
        .is_none_or(|e| e != "yaml" && e != "yml")
    {
        bail!(
            "--out {}: the map's file name must end in .yaml (its image goes beside it as .pgm)",
            args.out.display()
        );
    }
    let t0 = Instant::now();
    let options = CloudReadOptions {
        max_points: config.limits.max_cloud_points as u64,
        drop_invalid: args.drop_invalid,
        units: args.units,
        ..CloudReadOptions::default()
    };
    // Shown once the reader knows the cloud is large.
    let reading = ProgressBar::hidden();
    let cloud = read_cloud(&args.cloud, &options, &mut |done, total| {
        if total >= PROGRESS_POINTS && !args.quiet {
            if reading.is_hidden() {
                reading.set_draw_target(indicatif::ProgressDrawTarget::stderr());
                if let Ok(style) = ProgressStyle::with_template(
                    "{spinner} reading {bar:30} {human_pos}/{human_len} points {eta}",
                ) {
                    reading.set_style(style);
                }
            }
            reading.set_length(total);
            reading.set_position(done);
        }
    })?;
    reading.finish_and_clear();
    let read_s = t0.elapsed().as_secs_f64();
    let origins = origins(&cloud, args.origin);
    let projecting = bar(args.quiet, cloud.points.len() as u64, "projecting");
    let projection = project(&cloud.points, &origins, &params, &config, |done, total| {
        projecting.set_length(total);
        projecting.set_position(done);
    })
    .map_err(|e| anyhow!("{}: {e}", args.cloud.display()))?;
    projecting.finish_and_clear();
    if let Some(w) = fragmentation_warning(&cloud, &origins, &params, &config, &projection) {
        eprintln!("warning: {w}");
    }
    let notes = yaml_notes(args, &cloud, &projection, &params);
    let preview = match &args.preview {
        Some(path) => {
            let title = format!("cpsplan grid \u{2014} {}", file_name(&args.cloud));
            let png = render_map(&projection.grid, &title)
                .map_err(|e| anyhow!("--preview {}: {e}", path.display()))?;
            Some(write_temp(path, &png)?)
        }
        None => None,
    };
    // The source's frame beside the map, for `explore --cloud-out`.
    let t = params.transform;
    let frame = SourceFrame {
        format: FRAME_FORMAT.into(),
        source: args.cloud.display().to_string(),
        metres_per_unit: cloud.metres_per_unit,
        transform: [t.tx, t.ty, t.yaw],
        ground: FrameGround::of(&projection.ground, projection.grid.geometry()),
        crs: cloud.crs.clone(),
    };
    let frame_path = SourceFrame::path_beside(&args.out);
    let mut frame_json = serde_json::to_string_pretty(&frame)?;
    frame_json.push('\n');
    let frame_file = write_temp(&frame_path, frame_json.as_bytes())?;
    save_map_with_notes(&projection.grid, &args.out, &notes)?;
    frame_file.persist(&frame_path)?;
    if let (Some(path), Some(png)) = (&args.preview, preview) {
        png.persist(path)?;
    }
    if !args.quiet {
        print_summary(
            args,
            &cloud,
            &projection,
            read_s,
            t0.elapsed().as_secs_f64(),
        );
    }
    Ok(())
}

/// Coarser cells tried when the free space falls apart, as multiples of the
/// resolution asked for.
const COARSER: [f64; 3] = [2.0, 3.0, 4.0];

/// The warning for a map whose free space is fragmented (points too sparse
/// for the cells: gaps of unknown cells between free ones, which block sight
/// and driving, or pieces the robots cannot drive between), with the finest
/// resolution of [`COARSER`] that mends it, found by projecting again.
fn fragmentation_warning(
    cloud: &Cloud,
    origins: &[BeamOrigin],
    params: &ProjectionParams,
    config: &Config,
    projection: &Projection,
) -> Option<String> {
    let pieces = free_space_pieces(&projection.grid);
    if !pieces.fragmented() {
        return None;
    }
    let better = COARSER.iter().find_map(|&k| {
        let coarser = ProjectionParams {
            resolution: params.resolution * k,
            ..*params
        };
        let p = project(&cloud.points, origins, &coarser, config, |_, _| {}).ok()?;
        let pieces = free_space_pieces(&p.grid);
        (!pieces.fragmented()).then_some((coarser.resolution, pieces))
    });
    let fix = match better {
        Some((r, p)) => format!(
            "--resolution {} leaves {:.1} % gaps and {:.0} % in one piece",
            number(r),
            100.0 * p.gap_share(),
            100.0 * p.largest_share()
        ),
        None => format!(
            "no resolution up to {} m mends it: lower --min-points, or with scans taken from \
             the ground add --free-from-scans",
            number(params.resolution * COARSER[COARSER.len() - 1])
        ),
    };
    Some(format!(
        "the free space is fragmented: {:.1} % of it is gaps (unknown cells between free ones, \
         more than {:.0} %) and its largest 4-connected piece holds {:.1} % of the {} free cells \
         ({} pieces; fewer than {:.0} % is fragmented): the points lie farther apart than the {} m \
         cells, and gaps block sight and driving as walls do; {fix}",
        100.0 * pieces.gap_share(),
        100.0 * GAPPY_SHARE,
        100.0 * pieces.largest_share(),
        pieces.free_cells,
        pieces.pieces,
        100.0 * FRAGMENTED_SHARE,
        number(params.resolution)
    ))
}

/// The file name of `path` (the whole path when it has none).
fn file_name(path: &Path) -> String {
    path.file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| path.display().to_string())
}

/// The comment lines of the map's YAML: where it came from and how.
fn yaml_notes(
    args: &GridArgs,
    cloud: &Cloud,
    p: &Projection,
    params: &ProjectionParams,
) -> Vec<String> {
    let mut notes = vec![format!(
        "cpsplan grid from {} ({}, {} points); map coordinates are the cloud's, in metres",
        args.cloud.display(),
        cloud.format.name(),
        cloud.points_in_file
    )];
    notes.extend(cloud.notes.iter().cloned());
    let band = match params.band {
        HeightBand::Absolute { min, max } => format!("obstacles from z = {min} m to {max} m"),
        HeightBand::AboveGround { low, high } => {
            format!("obstacles from {low} m to {high} m above the ground")
        }
    };
    notes.push(format!(
        "{band}; ground: {}; min points {}",
        p.ground.describe(),
        params.min_points
    ));
    let t = params.transform;
    if t != PlanarTransform::default() {
        notes.push(format!(
            "cloud moved by --transform {},{},{} (yaw in radians) before projecting",
            t.tx, t.ty, t.yaw
        ));
    }
    notes
}

fn print_summary(args: &GridArgs, cloud: &Cloud, p: &Projection, read_s: f64, total_s: f64) {
    let s = &p.stats;
    let g = p.grid.geometry();
    println!(
        "{}: {} points read ({}{}), {} kept{}",
        args.cloud.display(),
        cloud.points_in_file,
        cloud.format.name(),
        if cloud.scans.len() > 1 {
            format!(", {} scans", cloud.scans.len())
        } else {
            String::new()
        },
        s.points_kept,
        match (cloud.points_dropped, s.outliers) {
            (0, 0) => String::new(),
            (d, 0) => format!(" ({d} invalid dropped)"),
            (0, o) => format!(" ({o} outliers dropped)"),
            (d, o) => format!(" ({d} invalid and {o} outliers dropped)"),
        }
    );
    for note in &cloud.notes {
        println!("note: {note}");
    }
    println!(
        "points: {} obstacle, {} ground, {} above the band{}",
        s.obstacle_points,
        s.ground_points,
        s.above_points,
        if s.beams > 0 {
            format!("; {} beams traced", s.beams)
        } else {
            String::new()
        }
    );
    println!("ground: {}", p.ground.describe());
    println!(
        "map: {} × {} cells of {} m ({} m × {} m), origin ({:.3}, {:.3}): {} free, {} occupied, {} unknown",
        g.width,
        g.height,
        g.resolution,
        approx(g.width as f64 * g.resolution),
        approx(g.height as f64 * g.resolution),
        g.origin.x,
        g.origin.y,
        s.free_cells,
        s.occupied_cells,
        s.unknown_cells
    );
    let rate = cloud.points_in_file as f64 / total_s.max(1e-9);
    println!(
        "written to {} in {:.2} s (reading {:.2} s, {:.2} M points/s overall)",
        args.out.display(),
        total_s,
        read_s,
        rate / 1e6
    );
}
