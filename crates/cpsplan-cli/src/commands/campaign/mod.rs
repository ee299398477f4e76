//! `cpsplan campaign`: a real team's campaign, one scan at a time
//! (docs/USER-GUIDE.md "Campaigns"). `init` creates the directory, `add`
//! takes a scan's cloud and the total station's readings and plans the next
//! step, `status` tells where the campaign stands, `export` writes the
//! registered model, the knowledge map and the episode page.

mod add;
#[cfg(feature = "ros")]
pub mod live;
mod next;
mod show;
mod store;

use std::path::{Path, PathBuf};

use anyhow::{anyhow, bail, Context, Result};
use clap::{Args, Subcommand};
use cpsplan::grid::{CellState, GridGeometry};
use cpsplan::{OccupancyGrid, Point};

use super::{load_planning_grid, read_config, validate};
use crate::args::{parse_point, parse_wall_band};
use crate::formats::rosmap::encode_map;
use store::{CampaignFile, Change, FORMAT, VERSION};

pub use store::STATE;

/// Options of `cpsplan campaign`.
#[derive(Debug, Args)]
pub struct CampaignArgs {
    /// What to do.
    #[command(subcommand)]
    pub command: CampaignCommand,
}

/// The campaign's subcommands.
#[derive(Debug, Subcommand)]
pub enum CampaignCommand {
    /// Create a campaign directory: the datum, the grid, the configuration.
    Init(InitArgs),
    /// Add one scan (its cloud in the scanner's frame and the total station's
    /// readings since the scan before) and plan the next step.
    Add(add::AddArgs),
    /// Scans, known area, σ of every station, hours so far, what comes next.
    Status(show::StatusArgs),
    /// Write the registered model, the knowledge map and the episode page.
    Export(show::ExportArgs),
}

/// Options of `cpsplan campaign init`.
#[derive(Debug, Args)]
pub struct InitArgs {
    /// The campaign's directory (created; an existing one must be empty).
    #[arg(value_name = "DIR")]
    pub dir: PathBuf,
    /// Where the parent stands for the first scan (the datum), metres.
    #[arg(long, value_name = "X,Y", value_parser = parse_point)]
    pub start: Point,
    /// Where the total station's zero points at the start, degrees
    /// counter-clockwise from the map's x axis.
    #[arg(
        long,
        value_name = "DEG",
        default_value_t = 0.0,
        allow_negative_numbers = true
    )]
    pub heading: f64,
    /// A map of what is known before the first scan (ROS YAML or image); its
    /// grid is the campaign's.
    #[arg(long, value_name = "MAP.yaml")]
    pub prior: Option<PathBuf>,
    /// The area the campaign may cover, metres [default: 100 m square about the
    /// start]; without --prior.
    #[arg(long, value_name = "X0,Y0,X1,Y1", conflicts_with = "prior")]
    pub area: Option<Area>,
    /// The planning configuration (TOML, as for explore).
    #[arg(long, value_name = "FILE.toml")]
    pub config: Option<PathBuf>,
    /// The seed of the planner's random choices (config `seed`).
    #[arg(long)]
    pub seed: Option<u64>,
    /// The heights above the floor whose points are walls, metres.
    #[arg(long, value_name = "LOW,HIGH", default_value = "0.3,2.0", value_parser = parse_wall_band)]
    pub wall_band: [f64; 2],
    /// The start's station name in the readings.
    #[arg(long, value_name = "NAME", default_value = "S0000")]
    pub datum: String,
}

/// A rectangle of the world, metres.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Area {
    /// Lower-left corner.
    pub min: Point,
    /// Upper-right corner.
    pub max: Point,
}

impl std::str::FromStr for Area {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        let v: Vec<f64> = s
            .split(',')
            .map(|t| t.trim().parse::<f64>().ok().filter(|v| v.is_finite()))
            .collect::<Option<_>>()
            .ok_or_else(|| format!("expected X0,Y0,X1,Y1 in metres, got `{s}`"))?;
        let [x0, y0, x1, y1] = v.as_slice() else {
            return Err(format!("expected X0,Y0,X1,Y1 in metres, got `{s}`"));
        };
        if x1 <= x0 || y1 <= y0 {
            return Err(format!("`{s}`: X1 must exceed X0 and Y1 exceed Y0"));
        }
        Ok(Self {
            min: Point::new(*x0, *y0),
            max: Point::new(*x1, *y1),
        })
    }
}

/// Half the side of the default area, metres.
const DEFAULT_HALF_SIDE_M: f64 = 50.0;

/// Runs a campaign subcommand.
pub fn run(args: &CampaignArgs) -> Result<()> {
    match &args.command {
        CampaignCommand::Init(a) => init(a),
        CampaignCommand::Add(a) => add::run(a),
        CampaignCommand::Status(a) => show::status(a),
        CampaignCommand::Export(a) => show::export(a),
    }
}

/// The grid of `area` at `resolution`: whole cells covering it (a side within
/// a millionth of a whole number of cells is that number).
fn area_grid(area: Area, resolution: f64) -> Result<GridGeometry> {
    let cells = |extent: f64| -> Result<usize> {
        let n = extent / resolution;
        let whole = if (n - n.round()).abs() < 1e-6 {
            n.round()
        } else {
            n.ceil()
        };
        if !(1.0..=1e9).contains(&whole) {
            bail!("--area: {extent} m is not a usable side at {resolution} m cells");
        }
        Ok(whole as usize)
    };
    let width = cells(area.max.x - area.min.x)?;
    let height = cells(area.max.y - area.min.y)?;
    Ok(GridGeometry::new(width, height, resolution, area.min))
}

/// `cpsplan campaign init`.
fn init(args: &InitArgs) -> Result<()> {
    check_empty(&args.dir)?;
    let file = read_config(args.config.as_deref())?;
    let mut config = file.config;
    if let Some(s) = args.seed {
        config.seed = s;
    }
    validate(&config, &[])?;
    if config.parent.planner == cpsplan::config::Planner::Oracle {
        bail!("the oracle planner needs the ground truth: a campaign plans for a real team");
    }
    if !cpsplan::accuracy::Reading::valid_name(&args.datum) {
        bail!(
            "--datum: `{}` is not a station name (letters, digits, . _ - :)",
            args.datum
        );
    }
    if !args.heading.is_finite() {
        bail!("--heading: not a number");
    }
    let mut change = Change::default();
    let (grid, prior) = match &args.prior {
        Some(path) => {
            let prior = load_planning_grid(path, &config)?;
            let encoded = encode_map(
                &prior,
                Path::new("prior.yaml"),
                &[format!("prior of the campaign, from {}", path.display())],
            )?;
            change.put("prior.yaml", encoded.yaml.into_bytes());
            change.put("prior.pgm", encoded.pgm);
            (*prior.geometry(), Some(prior))
        }
        None => {
            let h = DEFAULT_HALF_SIDE_M;
            let area = args.area.unwrap_or(Area {
                min: Point::new(args.start.x - h, args.start.y - h),
                max: Point::new(args.start.x + h, args.start.y + h),
            });
            (area_grid(area, config.resolution)?, None)
        }
    };
    grid.check_limits(&config).map_err(|e| anyhow!(e))?;
    let cell = grid.world_to_cell(args.start).ok_or_else(|| {
        anyhow!(
            "--start ({}, {}) is outside the campaign's area",
            args.start.x,
            args.start.y
        )
    })?;
    if let Some(p) = &prior {
        if p.get(cell) == CellState::Occupied {
            bail!("--start lies on an occupied cell of the prior map");
        }
    }
    let empty = OccupancyGrid::filled(grid, CellState::Unknown);
    let state = CampaignFile {
        format: FORMAT.into(),
        version: VERSION,
        start: grid.cell_center(cell),
        heading_deg: args.heading,
        datum: args.datum.clone(),
        wall_band_m: args.wall_band,
        grid,
        prior: prior.is_some(),
        config,
        scans: Vec::new(),
    };
    let knowledge = prior.unwrap_or(empty);
    let encoded = encode_map(&knowledge, Path::new("knowledge.yaml"), &[])?;
    change.put("knowledge.yaml", encoded.yaml.into_bytes());
    change.put("knowledge.pgm", encoded.pgm);
    change.commit(&args.dir, &state)?;
    println!(
        "campaign {}: start ({:.2}, {:.2}), {} × {} cells of {} m; add the first scan with \
         `cpsplan campaign add {} --scan FILE --readings FILE.csv`",
        args.dir.display(),
        state.start.x,
        state.start.y,
        grid.width,
        grid.height,
        grid.resolution,
        args.dir.display()
    );
    Ok(())
}

/// Refuses a path that exists and is not an empty directory (the directory
/// is created when the campaign is written).
fn check_empty(dir: &Path) -> Result<()> {
    match std::fs::read_dir(dir) {
        Ok(mut entries) => {
            if entries.next().is_some() {
                bail!(
                    "{} is not empty: a campaign starts in a new directory",
                    dir.display()
                );
            }
            Ok(())
        }
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(()),
        Err(_) if dir.exists() => bail!("{} is not a directory", dir.display()),
        Err(e) => Err(e).with_context(|| format!("cannot read {}", dir.display())),
    }
}
