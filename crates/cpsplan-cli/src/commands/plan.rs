//! `cpsplan plan`: one step for a real team on a partial map, printed as JSON.

use std::io::Write as _;

use anyhow::{bail, Context, Result};

use super::{load_planning_grid, read_config, validate};
use crate::cli::PlanArgs;
use crate::render::{render_step, StepView};
use crate::report::write_temp;

/// Plans the step and prints it; with `--figure`, draws it too. The figure
/// is moved into place only once the plan has been printed.
pub fn run(args: &PlanArgs) -> Result<()> {
    let file = read_config(args.config.as_deref())?;
    let mut config = file.config.clone();
    if file.sets("children.count") && config.children.count != args.children.len() {
        bail!(
            "the config file sets children.count = {}, but {} --child position{} given; \
             give one --child per child or remove children.count from the file",
            config.children.count,
            args.children.len(),
            if args.children.len() == 1 {
                " is"
            } else {
                "s are"
            }
        );
    }
    config.children.count = args.children.len();
    if let Some(p) = args.preset {
        p.apply(&mut config, |k| file.sets(k));
    }
    if let Some(r) = args.resolution {
        config.resolution = r;
    }
    if let Some(s) = args.seed {
        config.seed = s;
    }
    if let Some(p) = args.planner {
        config.parent.planner = p;
    }
    if let Some(s) = args.child_strategy {
        config.children.strategy = s;
    }
    if let Some(m) = args.instrument {
        config.instrument.model = m;
    }
    if config.parent.planner == cpsplan::config::Planner::Oracle {
        bail!(
            "the oracle planner knows what each scan would reveal from the ground truth: \
             it is a yardstick for simulated episodes (`explore`, experiments), not a plan for a real team"
        );
    }
    validate(
        &config,
        &[
            ("resolution", "--resolution", args.resolution.is_some()),
            ("children.count", "--child", true),
        ],
    )?;
    let known = load_planning_grid(&args.known, &config)?;
    let step = cpsplan::mission::plan_step(&known, args.parent, &args.children, &config)?;
    let figure = match &args.figure {
        Some(path) => {
            let view = StepView::planned(&step, args.parent, &args.children);
            let name = args.known.file_name().map_or_else(
                || args.known.display().to_string(),
                |n| n.to_string_lossy().into_owned(),
            );
            let title = format!("cpsplan plan \u{2014} {name}");
            let png = render_step(&known, &view, &config, &title)?;
            Some((path, write_temp(path, &png)?))
        }
        None => None,
    };
    let mut out = serde_json::to_string_pretty(&step)?;
    out.push('\n');
    let printed = std::io::stdout()
        .write_all(out.as_bytes())
        .and_then(|()| std::io::stdout().flush())
        .context("cannot write the plan");
    match (printed, figure) {
        (Ok(()), Some((path, tmp))) => tmp.persist(path),
        (Ok(()), None) => Ok(()),
        (Err(e), _) => Err(e),
    }
}
