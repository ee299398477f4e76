//! The library's layout rule (docs/DESIGN-CHOICES.md "Architecture"): the stages
//! follow the paper's pipeline, every module imports only from stages below its
//! own, and no two files import each other, directly or through others.

use std::collections::{BTreeMap, BTreeSet};
use std::fs;
use std::path::{Path, PathBuf};

/// The stages, bottom first.
const STAGES: [&str; 13] = [
    "geom", "config", "grid", "world", "sensing", "accuracy", "parent", "children", "subgoals",
    "motion", "mission", "model", "bound",
];

/// Modules that import nothing from the crate and may be used by every stage.
const FOUNDATION: [&str; 2] = ["geom", "config"];

fn rank(stage: &str) -> Option<usize> {
    if FOUNDATION.contains(&stage) {
        return Some(0);
    }
    STAGES.iter().position(|&s| s == stage)
}

fn src() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("src")
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in fs::read_dir(dir).expect("source folder is readable") {
        let path = entry.expect("entry is readable").path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The file's code lines: comments and doc comments removed.
fn code(text: &str) -> Vec<&str> {
    text.lines()
        .map(|l| l.split("//").next().unwrap_or(""))
        .filter(|l| !l.trim().is_empty())
        .collect()
}

/// The words that follow each `prefix` in `line` (`crate::grid::x` with prefix
/// `crate::` gives `grid`).
fn after<'a>(line: &'a str, prefix: &str) -> Vec<&'a str> {
    let mut out = Vec::new();
    let mut rest = line;
    while let Some(i) = rest.find(prefix) {
        let tail = &rest[i + prefix.len()..];
        let end = tail
            .find(|c: char| !(c.is_alphanumeric() || c == '_'))
            .unwrap_or(tail.len());
        out.push(&tail[..end]);
        rest = &tail[end..];
    }
    out
}

/// (stage, file module) of a source file: `grid/travel.rs` is ("grid", "travel"),
/// `grid/mod.rs` ("grid", "mod"), `geom.rs` ("geom", "mod").
fn place(path: &Path) -> (String, String) {
    let rel = path.strip_prefix(src()).expect("under src");
    let parts: Vec<String> = rel
        .iter()
        .map(|p| p.to_string_lossy().trim_end_matches(".rs").to_string())
        .collect();
    match parts.as_slice() {
        [file] => (file.clone(), "mod".into()),
        [stage, rest @ ..] => (stage.clone(), rest.join("/")),
        [] => unreachable!("a file has a name"),
    }
}

#[test]
fn every_import_goes_down_the_pipeline() {
    let mut files = Vec::new();
    rust_files(&src(), &mut files);
    assert!(files.len() > 30, "found only {} files", files.len());
    let mut wrong = Vec::new();
    for path in &files {
        let (stage, _) = place(path);
        if stage == "lib" {
            continue;
        }
        let own = rank(&stage).unwrap_or_else(|| panic!("{stage} is not a known stage"));
        let text = fs::read_to_string(path).expect("readable");
        for line in code(&text) {
            for used in after(line, "crate::") {
                let Some(r) = rank(used) else { continue };
                let foundation_imports = FOUNDATION.contains(&stage.as_str()) && used != stage;
                if (r > own || foundation_imports) && used != stage {
                    wrong.push(format!("{}: {}", path.display(), line.trim()));
                }
            }
        }
    }
    assert!(wrong.is_empty(), "imports going up:\n{}", wrong.join("\n"));
}

#[test]
fn no_two_files_import_each_other() {
    let mut files = Vec::new();
    rust_files(&src(), &mut files);
    // Edges between the files of one stage (mod.rs, which only declares and
    // re-exports, left out), from their code outside the unit tests.
    let mut modules: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    let mut edges: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for path in &files {
        let (stage, module) = place(path);
        if module != "mod" {
            modules.entry(stage).or_default().insert(module);
        }
    }
    for path in &files {
        let (stage, module) = place(path);
        if module == "mod" || module.contains('/') {
            continue;
        }
        let siblings = &modules[&stage];
        let text = fs::read_to_string(path).expect("readable");
        let main = text.split("#[cfg(test)]").next().unwrap_or("");
        for line in code(main) {
            let mut used = after(line, "super::");
            used.extend(after(line, &format!("crate::{stage}::")));
            for u in used {
                if u != module && siblings.contains(u) {
                    edges
                        .entry(format!("{stage}::{module}"))
                        .or_default()
                        .insert(format!("{stage}::{u}"));
                }
            }
        }
    }
    assert!(
        edges.values().map(BTreeSet::len).sum::<usize>() > 10,
        "the scan found too few imports: {edges:?}"
    );
    // Depth-first search for a cycle.
    fn visit(
        node: &str,
        edges: &BTreeMap<String, BTreeSet<String>>,
        state: &mut BTreeMap<String, u8>,
        path: &mut Vec<String>,
    ) -> Option<Vec<String>> {
        match state.get(node) {
            Some(1) => {
                let start = path.iter().position(|p| p == node).unwrap_or(0);
                let mut cycle = path[start..].to_vec();
                cycle.push(node.to_string());
                return Some(cycle);
            }
            Some(_) => return None,
            None => {}
        }
        state.insert(node.to_string(), 1);
        path.push(node.to_string());
        for next in edges.get(node).into_iter().flatten() {
            if let Some(c) = visit(next, edges, state, path) {
                return Some(c);
            }
        }
        path.pop();
        state.insert(node.to_string(), 2);
        None
    }
    let mut state = BTreeMap::new();
    for node in edges.keys() {
        let mut path = Vec::new();
        if let Some(cycle) = visit(node, &edges, &mut state, &mut path) {
            panic!("import cycle: {}", cycle.join(" -> "));
        }
    }
}
