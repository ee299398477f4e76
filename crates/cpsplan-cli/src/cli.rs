//! Command-line interface: the subcommands and their parsing. Each
//! subcommand's arguments and work are in its module of [`crate::commands`];
//! the value parsers they share are in [`crate::args`].

use anyhow::Result;
use clap::{CommandFactory, Parser, Subcommand};

use crate::commands;
use crate::commands::{bound, experiment, explore, grid, maps, plan, report};
pub use crate::errors::{one_line, UsageError};

/// Scan planning for a cooperative multi-robot laser-scanning team (CPS-SLAM).
#[derive(Debug, Parser)]
#[command(name = "cpsplan", version, about, propagate_version = true)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// The subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Simulate a whole scanning campaign on a map and write its report.
    Explore(explore::ExploreArgs),
    /// List the built-in maps, or export them as ROS maps and previews.
    Maps(maps::MapsArgs),
    /// Plan one step for a real team on a partial map; prints the plan as JSON.
    Plan(plan::PlanArgs),
    /// List the instrument presets with their accuracy and range.
    Instruments(commands::instruments::InstrumentsArgs),
    /// Project a 3D point cloud (LAS, LAZ, E57, PLY, PCD) to a ROS map_server
    /// map (PGM + YAML) that explore and plan load.
    Grid(grid::GridArgs),
    /// The known-map yardstick: how few scan stations cover the map when it is
    /// known beforehand (greedy set cover and an LP lower bound).
    Bound(bound::BoundArgs),
    /// Run the episodes of an experiment file in parallel, one record each as it
    /// finishes (`experiment merge` joins the directories of its shards).
    Experiment(experiment::ExperimentArgs),
    /// Plots and tables of an experiment's records: coverage, travel, error and
    /// campaign time against the scans, per map and condition, as SVG and PNG, and
    /// the headline figures as Markdown and CSV.
    Report(report::ReportArgs),
    /// A real team's campaign, one scan at a time: `init` a directory, `add`
    /// each scan's cloud and total-station readings to get the next plan,
    /// `status`, `export` the registered model, the map and the page.
    Campaign(commands::campaign::CampaignArgs),
    /// A campaign as a live ROS 2 node: scans and readings in, the next plan,
    /// the map and the registered scans out (pure Rust DDS, no ROS needed).
    #[cfg(feature = "ros")]
    Ros(commands::campaign::live::RosArgs),
    /// Print every configuration key with its default value, as the TOML file
    /// that `--config` reads.
    Config,
    /// Print the shell completions of cpsplan (bash, zsh, fish, elvish,
    /// powershell), e.g. `cpsplan completions bash > ~/.local/share/bash-completion/completions/cpsplan`.
    Completions(commands::completions::CompletionsArgs),
}

/// Parses `args` (the program name first); help and version requests print
/// and exit, every other problem becomes a one-line [`UsageError`].
pub fn parse<I, T>(args: I) -> Result<Cli>
where
    I: IntoIterator<Item = T>,
    T: Into<std::ffi::OsString> + Clone,
{
    use clap::error::ErrorKind;
    let args: Vec<std::ffi::OsString> = args.into_iter().map(Into::into).collect();
    let command = args
        .iter()
        .skip(1)
        .filter_map(|a| a.to_str())
        .find(|a| {
            [
                "explore",
                "plan",
                "maps",
                "instruments",
                "grid",
                "bound",
                "experiment",
                "report",
                "campaign",
                "ros",
            ]
            .contains(a)
        })
        .map_or_else(|| "cpsplan".to_string(), |c| format!("cpsplan {c}"));
    match Cli::try_parse_from(args) {
        Ok(cli) => Ok(cli),
        Err(e) => match e.kind() {
            ErrorKind::DisplayHelp
            | ErrorKind::DisplayVersion
            | ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand => e.exit(),
            _ => Err(UsageError(usage_line(&e.render().to_string(), &command)).into()),
        },
    }
}

/// Clap's several-line message as one line: the error, and where to find help.
fn usage_line(rendered: &str, command: &str) -> String {
    // The message is everything before the first blank line (a list of missing
    // arguments follows its first line).
    let message: Vec<&str> = rendered
        .lines()
        .map(str::trim)
        .skip_while(|l| l.is_empty())
        .take_while(|l| !l.is_empty())
        .collect();
    let first = message.join(" ");
    let first = first.strip_prefix("error: ").unwrap_or(&first);
    let first = if first.is_empty() {
        "bad arguments"
    } else {
        first
    };
    let tip = rendered
        .lines()
        .map(str::trim)
        .find_map(|l| l.strip_prefix("tip: "))
        .map(|t| format!(" ({t})"))
        .unwrap_or_default();
    format!("{first}{tip}; see `{command} --help`")
}

/// Parses the process arguments and runs the command.
pub fn run() -> Result<()> {
    run_args(std::env::args_os())
}

/// Runs the command line `args` (the program's name first) as `cpsplan`
/// does: the entry point of the Python package.
pub fn run_args<I, T>(args: I) -> Result<()>
where
    I: IntoIterator<Item = T>,
    T: Into<std::ffi::OsString> + Clone,
{
    match parse(args)?.command {
        Command::Explore(args) => commands::explore::run(&args),
        Command::Maps(args) => commands::maps::run(&args),
        Command::Plan(args) => commands::plan::run(&args),
        Command::Instruments(args) => commands::instruments::run(&args),
        Command::Grid(args) => commands::grid::run(&args),
        Command::Bound(args) => commands::bound::run(&args),
        Command::Experiment(args) => commands::experiment::run(&args),
        Command::Report(args) => commands::report::run(&args),
        Command::Campaign(args) => commands::campaign::run(&args),
        #[cfg(feature = "ros")]
        Command::Ros(args) => commands::campaign::live::run(&args),
        Command::Config => commands::defaults::print_config(),
        Command::Completions(args) => commands::completions::run(&args, Cli::command()),
    }
}
