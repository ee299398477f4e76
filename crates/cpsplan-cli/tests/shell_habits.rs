//! What a shell user reaches for: JSON lists, completions, the configuration's
//! defaults at hand, and help that names no file an installed binary lacks.

use std::path::Path;

use serde_json::Value;

mod common;
use common::{cpsplan, run, run_ok};

#[test]
fn instruments_and_maps_list_as_json() {
    let table = run_ok(&["instruments"]);
    let json: Value = serde_json::from_str(&run_ok(&["instruments", "--json"])).unwrap();
    let presets = json.as_array().unwrap();
    assert_eq!(
        presets.len(),
        table.lines().count() - 1,
        "one per table row"
    );
    for p in presets {
        let name = p["name"].as_str().unwrap();
        assert!(table.contains(name), "{name}");
        for key in ["distance_sigma_mm", "angle_sigma_arcsec", "max_range_m"] {
            assert!(p[key].as_f64().unwrap() > 0.0, "{name} {key}");
        }
        assert!(p["min_range_m"].as_f64().unwrap() < p["max_range_m"].as_f64().unwrap());
    }
    let maps: Value = serde_json::from_str(&run_ok(&["maps", "--json"])).unwrap();
    let names: Vec<&str> = maps
        .as_array()
        .unwrap()
        .iter()
        .map(|m| m["name"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["office", "site", "tunnel"]);
    assert!(maps[1]["start"]["x"].is_f64());
}

#[test]
fn completions_cover_every_subcommand_and_flag() {
    let bash = run_ok(&["completions", "bash"]);
    for word in [
        "explore",
        "campaign",
        "--cloud-out",
        "--children",
        "--force",
    ] {
        assert!(bash.contains(word), "{word}");
    }
    for shell in ["zsh", "fish", "elvish", "powershell"] {
        assert!(
            run_ok(&["completions", shell]).contains("cpsplan"),
            "{shell}"
        );
    }
    let (ok, _, err) = run(&["completions", "tcsh"]);
    assert!(!ok && err.contains("tcsh"), "{err}");
}

/// `cpsplan config` prints a file `--config` reads back to the defaults.
#[test]
fn the_printed_configuration_reads_back_to_the_defaults() {
    let text = run_ok(&["config"]);
    let file = cpsplan_cli::formats::config::parse_config(&text, Path::new("defaults.toml"))
        .expect("the printed configuration parses");
    assert_eq!(file.config, cpsplan::Config::default());
    for section in ["[scanner]", "[parent]", "[children]", "[limits]"] {
        assert!(text.contains(section), "{section}");
    }
}

/// After `cargo install` there is no docs/ beside the binary: no help text
/// sends the user there.
#[test]
fn help_names_no_file_of_the_sources() {
    let top = run_ok(&["--help"]);
    let commands: Vec<String> = top
        .lines()
        .skip_while(|l| !l.starts_with("Commands:"))
        .skip(1)
        .take_while(|l| !l.is_empty())
        .filter_map(|l| l.split_whitespace().next().map(str::to_string))
        .filter(|c| c != "help")
        .collect();
    assert!(commands.len() >= 10, "{commands:?}");
    for c in &commands {
        let out = cpsplan().args([c.as_str(), "--help"]).output().unwrap();
        let help = String::from_utf8_lossy(&out.stdout);
        assert!(!help.contains("docs/"), "cpsplan {c} --help: {help}");
    }
}

/// `cpsplan … | head` closes the pipe before the command has printed all: the
/// command ends quietly with 141 (128 + SIGPIPE, what a shell shows), not with
/// a panic and its backtrace. A pipe whose reader is already closed makes the
/// first write fail, whatever the timing.
#[test]
fn a_closed_output_pipe_ends_quietly() {
    for args in [vec!["config"], vec!["instruments"], vec!["maps", "--json"]] {
        let (reader, writer) = std::io::pipe().unwrap();
        drop(reader);
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_cpsplan"))
            .args(&args)
            .env("RUST_BACKTRACE", "1")
            .stdout(writer)
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(141), "{args:?}: {stderr}");
        assert!(stderr.is_empty(), "{args:?} printed: {stderr}");
    }
}
