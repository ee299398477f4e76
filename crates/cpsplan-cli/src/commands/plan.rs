//! `cpsplan plan`: one step for a real team on a partial map, printed as JSON.

use anyhow::{Context, Result};
use cpsplan::world::resample_conservative;

use super::read_config;
use crate::cli::PlanArgs;
use crate::formats::rosmap::load_any;
use crate::render::{render_step, StepView};
use crate::report::write_atomic;

/// Plans the step and prints it; with `--figure`, draws it too.
pub fn run(args: &PlanArgs) -> Result<()> {
    let mut config = read_config(args.config.as_deref())?;
    if let Some(r) = args.resolution {
        config.resolution = r;
    }
    if let Some(s) = args.seed {
        config.seed = s;
    }
    if let Some(s) = args.child_strategy {
        config.children.strategy = s;
    }
    if let Some(m) = args.instrument {
        config.instrument.model = m;
    }
    config.validate()?;
    let grid = load_any(&args.known, config.resolution)?;
    let known = resample_conservative(&grid, config.resolution);
    let step = cpsplan::mission::plan_step(&known, args.parent, &args.children, &config)?;
    if let Some(path) = &args.figure {
        let view = StepView::planned(&step, args.parent, &args.children);
        let name = args.known.file_name().map_or_else(
            || args.known.display().to_string(),
            |n| n.to_string_lossy().into_owned(),
        );
        let title = format!("cpsplan plan \u{2014} {name}");
        let png = render_step(&known, &view, &config, &title)?;
        write_atomic(path, &png)?;
    }
    let mut out = serde_json::to_string_pretty(&step)?;
    out.push('\n');
    use std::io::Write as _;
    std::io::stdout()
        .write_all(out.as_bytes())
        .context("cannot write the plan")?;
    Ok(())
}
