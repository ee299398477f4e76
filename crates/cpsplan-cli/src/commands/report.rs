//! `cpsplan report DIR`: the plots and tables of an experiment's records.
//!
//! Per map, one chart per figure against the scan number (coverage, parent
//! travel, predicted error, campaign time) and coverage against travel, each
//! condition a line (the median over its seeds) over a band (their quartiles), as
//! SVG and PNG; the headline figures of every condition as Markdown
//! (`summary.md`, with the charts) and CSV (`summary.csv`), and all of it in
//! one self-contained page (`report.html`, the charts inline). Written whole
//! into `--out` (default `DIR/report`).

use std::path::PathBuf;

use anyhow::{bail, Context, Result};
use clap::Args;

use crate::experiment::medians::medians_markdown_table;
use crate::experiment::oracle::oracle_markdown_table;
use crate::experiment::summary::{
    bound_markdown_table, conditions, csv_table, curve, curve_against, greedy_bound_curve,
    headline, html_of_markdown, html_table, markdown_table, Condition, Metric,
};
use crate::experiment::text::md_text;
use crate::experiment::{EpisodeRecord, ExperimentDir, Outcome, Plan, Shard};
use crate::html::episodes::{player_section, ShownEpisode};
use crate::html::{escape, page_data, page_title};
use crate::lock::OutLock;
use crate::render::{Chart, Series, SERIES_COLOURS};
use crate::report::{write_atomic, ReportDir};

/// Options of `cpsplan report`.
#[derive(Debug, Args)]
pub struct ReportArgs {
    /// The experiment's directory (the --out of `cpsplan experiment` or `experiment merge`).
    #[arg(value_name = "DIR")]
    pub dir: PathBuf,
    /// Where the report goes [default: DIR/report]; an earlier report there is replaced.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Put every episode page of the experiment (`experiment --html`) into
    /// report.html, not only each condition's typical episode.
    #[arg(long)]
    pub all_episodes: bool,
    /// Print nothing but errors and warnings.
    #[arg(long, short)]
    pub quiet: bool,
}

/// The page's style sheet.
const STYLE: &str =
    "body{font:14px/1.45 system-ui,sans-serif;color:#1f2933;margin:20px;max-width:1400px}\
table{border-collapse:collapse;font-variant-numeric:tabular-nums}\
td,th{border-bottom:1px solid #d9e2ec;padding:4px 6px;text-align:right;white-space:nowrap}\
th{white-space:normal;vertical-align:bottom;min-width:4.5em;max-width:9em}\
.wide{overflow-x:auto}\
td:first-child,th:first-child{text-align:left}th{background:#f5f7fa}\
.charts{display:grid;grid-template-columns:repeat(auto-fill,minmax(560px,1fr));gap:12px}\
figure{margin:0}figure svg{width:100%;height:auto;border:1px solid #d9e2ec;border-radius:6px}";

/// The colour of the known-map bound's line.
const BOUND_COLOUR: (u8, u8, u8) = (26, 26, 26);

/// What the table of medians says.
const MEDIANS_NOTE: &str = "Each condition's median over its finished episodes (seeds), with the \
least and the most in brackets: the figures by which planners are compared.";

/// What the table against the oracle says.
const ORACLE_NOTE: &str = "Each condition against the oracle of the same map, start, \
configuration but the planner, and instrument (`--planner oracle`: the explorer's candidates and reachability, each \
scan's gain the true one, the most true gain per unit of campaign time taken), seed by seed: \
scans and campaign hours until 99 % of the reachable free space was covered, and their ratio \
to the oracle's of the same seed (medians over the seeds, and the largest ratio).";

/// What the headline table says.
const HEADLINE_NOTE: &str = "Means over the seeds of each condition (± the standard deviation); \
    \"to 90 %\": scans until 90 % of the reachable free space was covered; \"m² per scan\" and \
    \"m² per m\": the free space covered per scan and per metre of parent travel.";

/// What the table against the bound says.
const BOUND_NOTE: &str = "The known-map yardstick of each episode's map and start (`cpsplan bound`): \
    the stations a greedy set cover that knew the map would need for 90 and 99 % of the coverable cells, \
    and the LP lower bound on the fewest; \"÷ greedy\": each episode's scans to that coverage over its \
    bound's greedy stations (episodes that got there). Means over the seeds.";

/// The per-scan figures drawn against the scan number.
const METRICS: [Metric; 4] = [
    Metric::Coverage,
    Metric::Travel,
    Metric::Error,
    Metric::Clock,
];

/// Whether `name` is a file `report` writes.
fn is_report_file(name: &str) -> bool {
    name == "summary.md"
        || name == "summary.csv"
        || name == "report.html"
        || [".svg", ".png"].iter().any(|ext| name.ends_with(ext))
}

/// [`file_part`] of every map, made unique: a map whose part another map
/// already has (`x y` and `x_y`) gets `-2`, `-3`, … in order.
fn file_parts(maps: &[&str]) -> Vec<String> {
    let mut out: Vec<String> = Vec::with_capacity(maps.len());
    for map in maps {
        let base = file_part(map);
        let mut part = base.clone();
        let mut k = 1;
        while out.contains(&part) {
            k += 1;
            part = format!("{base}-{k}");
        }
        out.push(part);
    }
    out
}

/// A map's name as it may stand in a file name.
fn file_part(name: &str) -> String {
    name.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect()
}

/// A line's style: its colour, and whether it is dashed.
type Style = ((u8, u8, u8), bool);

/// The line style of each of a map's conditions.
///
/// Conditions named by two or more axes (`team/paper`, `single/paper`, ...)
/// whose leading axes take two values get a colour for the last axis and a
/// dash for the second value of the others, so that a reader matches the
/// planners across the parameter sets at a glance; otherwise each condition
/// takes the next colour, dashed once the colours run out.
fn styles(conditions: &[&Condition<'_>]) -> Vec<Style> {
    let by_place = |k: usize| {
        (
            SERIES_COLOURS[k % SERIES_COLOURS.len()],
            (k / SERIES_COLOURS.len()) % 2 == 1,
        )
    };
    let split: Vec<Option<(&str, &str)>> = conditions
        .iter()
        .map(|c| c.within_map.rsplit_once('/'))
        .collect();
    let mut heads: Vec<&str> = Vec::new();
    let mut lasts: Vec<&str> = Vec::new();
    for (head, last) in split.iter().flatten() {
        if !heads.contains(head) {
            heads.push(head);
        }
        if !lasts.contains(last) {
            lasts.push(last);
        }
    }
    let two_axes = split.iter().all(Option::is_some)
        && heads.len() == 2
        && lasts.len() <= SERIES_COLOURS.len();
    split
        .iter()
        .enumerate()
        .map(|(k, parts)| match parts {
            Some((head, last)) if two_axes => lasts
                .iter()
                .position(|l| l == last)
                .map_or(by_place(k), |colour| {
                    (SERIES_COLOURS[colour], heads[0] != *head)
                }),
            _ => by_place(k),
        })
        .collect()
}

/// The series of `conditions` for one chart, styled by [`styles`]; conditions
/// whose curves are the same (the same scans with and without the team, say)
/// share one line, labelled with all their names.
fn series(
    conditions: &[&Condition<'_>],
    points: impl Fn(&Condition<'_>) -> Option<(Vec<(f64, f64)>, Vec<(f64, f64, f64)>)>,
) -> Vec<Series> {
    struct Line<'c> {
        names: Vec<&'c str>,
        episodes: Vec<usize>,
        series: Series,
    }
    let styles = styles(conditions);
    let mut lines: Vec<Line<'_>> = Vec::new();
    for (c, (colour, dashed)) in conditions.iter().zip(styles) {
        let Some((points, band)) = points(c) else {
            continue;
        };
        let episodes = c.records.len();
        match lines
            .iter_mut()
            .find(|l| l.series.points == points && l.series.band == band)
        {
            Some(same) => {
                same.names.push(&c.within_map);
                same.episodes.push(episodes);
            }
            None => lines.push(Line {
                names: vec![&c.within_map],
                episodes: vec![episodes],
                series: Series {
                    label: String::new(),
                    points,
                    colour,
                    dashed,
                    band,
                },
            }),
        }
    }
    lines
        .into_iter()
        .map(|mut l| {
            let same_count = l.episodes.windows(2).all(|w| w[0] == w[1]);
            l.series.label = match (l.names.len(), same_count) {
                (1, _) => format!("{} ({} ep.)", l.names[0], l.episodes[0]),
                (_, true) => format!("{} ({} ep. each)", l.names.join(" = "), l.episodes[0]),
                _ => l
                    .names
                    .iter()
                    .zip(&l.episodes)
                    .map(|(n, e)| format!("{n} ({e} ep.)"))
                    .collect::<Vec<_>>()
                    .join(" = "),
            };
            l.series
        })
        .collect()
}

/// The series of `metric` against the scan number: each condition's median
/// over its seeds with their quartiles as a band.
fn metric_series(conditions: &[&Condition<'_>], metric: Metric) -> Vec<Series> {
    series(conditions, |c| {
        curve(c, metric).map(|k| (k.median, k.quartiles))
    })
}

/// The typical episode of `condition`: of its finished episodes with a page,
/// the one with the median number of scans (the earlier of two).
fn typical<'a>(
    condition: &Condition<'a>,
    has_page: &dyn Fn(usize) -> bool,
) -> Option<&'a EpisodeRecord> {
    let mut finished: Vec<(usize, &EpisodeRecord)> = condition
        .records
        .iter()
        .filter(|r| has_page(r.episode.index))
        .filter_map(|r| match &r.outcome {
            Outcome::Finished { summary, .. } => Some((summary.scans, *r)),
            Outcome::Failed { .. } => None,
        })
        .collect();
    finished.sort_by_key(|(scans, r)| (*scans, r.episode.index));
    let middle = finished.len().checked_sub(1)? / 2;
    Some(finished[middle].1)
}

/// The episodes the page shows: every one with a page (`all`), or each
/// condition's typical one; with what the page says about them.
fn shown_episodes(
    dir: &ExperimentDir,
    conditions: &[Condition<'_>],
    all: bool,
) -> Result<(Vec<(usize, ShownEpisode)>, String)> {
    let has_page = |index: usize| dir.page_path(index).is_file();
    let chosen: Vec<&EpisodeRecord> = if all {
        conditions
            .iter()
            .flat_map(|c| c.records.iter().copied())
            .filter(|r| has_page(r.episode.index))
            .collect()
    } else {
        conditions
            .iter()
            .filter_map(|c| typical(c, &has_page))
            .collect()
    };
    let mut out = Vec::with_capacity(chosen.len());
    for r in chosen {
        let path = dir.page_path(r.episode.index);
        let page = std::fs::read_to_string(&path)
            .with_context(|| format!("cannot read {}", path.display()))?;
        let Some(data) = page_data(&page) else {
            eprintln!("warning: {} left out: not an episode page", path.display());
            continue;
        };
        let scans = match &r.outcome {
            Outcome::Finished { summary, .. } => summary.scans,
            Outcome::Failed { .. } => 0,
        };
        out.push((
            r.episode.index,
            ShownEpisode {
                label: format!("{} ({scans} scans)", r.episode.label),
                title: page_title(&dir.file.plan.name, &r.episode.label),
                data: data.to_string(),
            },
        ));
    }
    let note = if all {
        "Every episode with a page, scan by scan: the map as it grew, the robots and their paths, \
         the AND regions, the candidates by G and the error ellipses."
    } else {
        "The typical episode of each condition (the seed with the median number of scans), scan \
         by scan: the map as it grew, the robots and their paths, the AND regions, the candidates \
         by G and the error ellipses. cpsplan report --all-episodes puts in every episode's page."
    };
    Ok((out, note.to_string()))
}

/// The report of an experiment's records without its episode pages: what
/// `cpsplan report` writes, in memory.
pub struct Rendered {
    /// `summary.md`, whole.
    pub md: String,
    /// `report.html` up to its episodes' section (no closing tags).
    pub html: String,
    /// The charts: file name and bytes (an SVG and a PNG each).
    pub files: Vec<(PathBuf, Vec<u8>)>,
    /// `summary.csv`.
    pub csv: Vec<u8>,
}

/// Renders the report of `records`, finished episodes of `plan` (the slice
/// `shard` of it), grouped into conditions.
pub fn render(plan: &Plan, shard: Option<Shard>, records: &[EpisodeRecord]) -> Result<Rendered> {
    let all = conditions(records);
    let mut maps: Vec<&str> = Vec::new();
    for c in &all {
        if !maps.contains(&c.map.as_str()) {
            maps.push(&c.map);
        }
    }
    let mut md = format!(
        "# Experiment `{}`\n\n{}\n\n{} of {} episodes recorded{}.\n\n## Headline figures\n\n\
         {HEADLINE_NOTE}\n\n",
        md_text(&plan.name),
        md_text(&plan.description),
        records.len(),
        plan.episodes.len(),
        match shard {
            Some(s) if s.n > 1 => format!(" (shard {s})"),
            _ => String::new(),
        }
    );
    let rows: Vec<_> = all.iter().map(headline).collect();
    md.push_str(&markdown_table(&rows));
    let medians_table = medians_markdown_table(&all);
    md.push_str(&format!(
        "\n## Medians over seeds\n\n{MEDIANS_NOTE}\n\n{medians_table}"
    ));
    let bound_table = bound_markdown_table(&rows);
    if let Some(t) = &bound_table {
        md.push_str(&format!(
            "\n## Against the known-map bound\n\n{BOUND_NOTE}\n\n{t}"
        ));
    }
    let oracle_table = oracle_markdown_table(&all);
    if let Some(t) = &oracle_table {
        md.push_str(&format!("\n## Against the oracle\n\n{ORACLE_NOTE}\n\n{t}"));
    }
    let mut html = format!(
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n\
         <title>{name}</title>\n<style>{STYLE}</style>\n</head>\n<body>\n<h1>Experiment <code>{name}</code></h1>\n\
         <p>{description}</p>\n<p>{count}</p>\n<h2>Headline figures</h2>\n<p>{note}</p>\n\
         <div class=\"wide\">{table}</div>",
        name = escape(&plan.name),
        description = escape(&plan.description),
        note = escape(HEADLINE_NOTE),
        count = escape(&format!(
            "{} of {} episodes recorded.",
            records.len(),
            plan.episodes.len()
        )),
        table = html_table(&rows),
    );
    html.push_str(&format!(
        "\n<h2>Medians over seeds</h2>\n<p>{}</p>\n<div class=\"wide\">{}</div>",
        escape(MEDIANS_NOTE),
        html_of_markdown(&medians_table)
    ));
    if let Some(t) = &oracle_table {
        html.push_str(&format!(
            "\n<h2>Against the oracle</h2>\n<p>{}</p>\n<div class=\"wide\">{}</div>",
            escape(&ORACLE_NOTE.replace('`', "")),
            html_of_markdown(t)
        ));
    }
    if let Some(t) = &bound_table {
        html.push_str(&format!(
            "\n<h2>Against the known-map bound</h2>\n<p>{}</p>\n<div class=\"wide\">{}</div>",
            escape(&BOUND_NOTE.replace('`', "")),
            html_of_markdown(t)
        ));
    }
    let mut files: Vec<(PathBuf, Vec<u8>)> = Vec::new();
    for (map, part) in maps.iter().zip(file_parts(&maps)) {
        let here: Vec<&Condition<'_>> = all.iter().filter(|c| c.map == *map).collect();
        md.push_str(&format!("\n## {}\n\n", md_text(map)));
        html.push_str(&format!(
            "<h2>{}</h2>\n<div class=\"charts\">\n",
            escape(map)
        ));
        let subtitle = "median over the seeds, band: their middle half; \
                        an ended episode keeps its last value"
            .to_string();
        let mut charts: Vec<(String, Chart)> = Vec::new();
        let map_records: Vec<&EpisodeRecord> = here
            .iter()
            .flat_map(|c| c.records.iter().copied())
            .collect();
        let bound = greedy_bound_curve(&map_records);
        for metric in METRICS {
            let mut s = metric_series(&here, metric);
            if s.is_empty() {
                continue;
            }
            if let (Metric::Coverage, Some(points)) = (metric, &bound) {
                s.push(Series {
                    label: "known-map greedy cover (bound)".into(),
                    points: points.clone(),
                    colour: BOUND_COLOUR,
                    dashed: true,
                    band: Vec::new(),
                });
            }
            charts.push((
                format!("{}-{part}", metric.name()),
                Chart {
                    title: format!("{} \u{2014} {map}", plan.name),
                    subtitle: subtitle.clone(),
                    x_label: "scan".into(),
                    y_label: metric.axis().into(),
                    series: s,
                },
            ));
        }
        let s = series(&here, |c| {
            curve_against(c, Metric::Travel, Metric::Coverage).map(|p| (p, Vec::new()))
        });
        if !s.is_empty() {
            charts.push((
                format!("coverage-travel-{part}"),
                Chart {
                    title: format!("{} \u{2014} {map}", plan.name),
                    subtitle: "median coverage against the median parent travel, scan by scan"
                        .into(),
                    x_label: Metric::Travel.axis().into(),
                    y_label: Metric::Coverage.axis().into(),
                    series: s,
                },
            ));
        }
        for (name, chart) in charts {
            let svg = chart.svg();
            html.push_str(&format!("<figure>{svg}</figure>\n"));
            files.push((PathBuf::from(format!("{name}.svg")), svg.into_bytes()));
            files.push((PathBuf::from(format!("{name}.png")), chart.png()?));
            md.push_str(&format!("![{name}]({name}.png)\n\n"));
        }
        html.push_str("</div>\n");
    }
    let csv = csv_table(&rows)?;
    Ok(Rendered {
        md,
        html,
        files,
        csv,
    })
}

/// Runs `cpsplan report`.
pub fn run(args: &ReportArgs) -> Result<()> {
    let dir = ExperimentDir::open(&args.dir)?;
    let records = dir.records()?;
    for (path, why) in records.damaged.iter().chain(&records.foreign) {
        eprintln!("warning: {} left out: {why}", path.display());
    }
    let records: Vec<EpisodeRecord> = records.valid.into_values().map(|(_, r)| r).collect();
    if records.is_empty() {
        bail!("{} holds no finished record yet", args.dir.display());
    }
    let plan = &dir.file.plan;
    let out_dir = args.out.clone().unwrap_or_else(|| args.dir.join("report"));
    let _lock = OutLock::acquire(&out_dir)?;
    let report = ReportDir::create_for(&out_dir, is_report_file)?;
    let Rendered {
        md,
        mut html,
        files,
        csv,
    } = render(plan, dir.file.shard, &records)?;
    let all = conditions(&records);
    let (shown, note) = shown_episodes(&dir, &all, args.all_episodes)?;
    if shown.is_empty() {
        html.push_str(
            "\n<h2>Episodes</h2>\n<p>No episode pages: <code>cpsplan experiment FILE.toml --out DIR \
             --resume --html</code> adds them (it runs the finished episodes again).</p>\n",
        );
    } else {
        html.push_str(&player_section(&shown, &note)?);
    }
    for (name, bytes) in &files {
        write_atomic(&report.path().join(name), bytes)?;
    }
    html.push_str("</body>\n</html>\n");
    write_atomic(&report.path().join("summary.md"), md.as_bytes())?;
    write_atomic(&report.path().join("report.html"), html.as_bytes())?;
    write_atomic(&report.path().join("summary.csv"), &csv)?;
    report.commit()?;
    if !args.quiet {
        println!(
            "experiment `{}`: {} conditions of {} records, {} charts; report written to {}",
            plan.name,
            all.len(),
            records.len(),
            files.len() / 2,
            out_dir.display()
        );
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::experiment::spec::parse_plan;
    use crate::experiment::summary::tests::record;

    /// The styles of the conditions of `records` and their coverage lines.
    fn styles_and_lines(records: &[EpisodeRecord]) -> (Vec<Style>, Vec<Series>) {
        let all = conditions(records);
        let here: Vec<&Condition<'_>> = all.iter().collect();
        (styles(&here), metric_series(&here, Metric::Coverage))
    }

    #[test]
    fn maps_whose_names_sanitise_alike_get_charts_of_their_own() {
        let parts = file_parts(&["x y", "x_y", "x<y", "builtin:site", "x y"]);
        assert_eq!(parts, ["x_y", "x_y-2", "x_y-3", "builtin_site", "x_y-4"]);
    }

    #[test]
    fn planners_keep_a_colour_across_the_sets_and_equal_curves_share_a_line() {
        let plan = parse_plan(
            "name = \"x\"\nmaps = [\"builtin:site\"]\nplanners = [\"paper\", \"tour\"]\n\
             [[parameters]]\nname = \"team\"\n[[parameters]]\nname = \"single\"\n",
            std::path::Path::new("x.toml"),
        )
        .unwrap();
        let labels: Vec<&str> = plan.episodes.iter().map(|e| e.label.as_str()).collect();
        assert_eq!(
            labels,
            [
                "site/team/paper/seed0",
                "site/team/tour/seed0",
                "site/single/paper/seed0",
                "site/single/tour/seed0"
            ]
        );
        // The paper planner scans alike in both sets; the tour does not.
        let records = vec![
            record(&plan, 0, &[0.5, 1.0]),
            record(&plan, 1, &[0.6, 1.0]),
            record(&plan, 2, &[0.5, 1.0]),
            record(&plan, 3, &[0.7, 0.9, 1.0]),
        ];
        let (styles, lines) = styles_and_lines(&records);
        assert_eq!(
            styles,
            [
                (SERIES_COLOURS[0], false),
                (SERIES_COLOURS[1], false),
                (SERIES_COLOURS[0], true),
                (SERIES_COLOURS[1], true)
            ],
            "a colour per planner, dashed for the second set"
        );
        let labels: Vec<&str> = lines.iter().map(|s| s.label.as_str()).collect();
        assert_eq!(
            labels,
            [
                "team/paper = single/paper (1 ep. each)",
                "team/tour (1 ep.)",
                "single/tour (1 ep.)"
            ]
        );
        assert_eq!(
            (lines[2].colour, lines[2].dashed),
            (SERIES_COLOURS[1], true)
        );
        // One axis: a colour each, in order.
        let plan = parse_plan(
            "name = \"y\"\nmaps = [\"builtin:site\"]\nplanners = [\"paper\", \"tour\", \"gain\"]\n",
            std::path::Path::new("y.toml"),
        )
        .unwrap();
        let records: Vec<EpisodeRecord> = (0..3).map(|i| record(&plan, i, &[0.5, 1.0])).collect();
        let (styles, lines) = styles_and_lines(&records);
        assert_eq!(
            styles,
            [
                (SERIES_COLOURS[0], false),
                (SERIES_COLOURS[1], false),
                (SERIES_COLOURS[2], false)
            ]
        );
        assert_eq!(lines.len(), 1);
        assert_eq!(lines[0].label, "paper = tour = gain (1 ep. each)");
    }
}
