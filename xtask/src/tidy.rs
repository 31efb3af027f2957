//! Repository hygiene, checked as ordinary tests (`cargo test -p xtask`).
//!
//! Each test reads files of the workspace and names what is out of place, so
//! that the documents stay true as the code changes.

use std::fs;
use std::path::{Path, PathBuf};

use crate::project_root;

fn read(path: &Path) -> String {
    fs::read_to_string(path).unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()))
}

fn crate_dirs() -> Vec<PathBuf> {
    let mut dirs: Vec<PathBuf> = fs::read_dir(project_root().join("crates"))
        .expect("crates/ exists")
        .filter_map(|entry| entry.ok().map(|e| e.path()))
        .filter(|path| path.join("Cargo.toml").is_file())
        .collect();
    dirs.sort();
    dirs
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let path = entry.path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|ext| ext == "rs") {
            out.push(path);
        }
    }
}

/// The `name = spec` lines of one `[section]` of a TOML manifest, as (name, spec).
fn section_entries(manifest: &str, section: &str) -> Vec<(String, String)> {
    let mut in_section = false;
    let mut entries = Vec::new();
    for line in manifest.lines() {
        let line = line.trim();
        if line.starts_with('[') {
            in_section = line == section;
            continue;
        }
        if !in_section || line.is_empty() || line.starts_with('#') {
            continue;
        }
        if let Some((name, spec)) = line.split_once(['=', '.']) {
            entries.push((name.trim().to_owned(), spec.to_owned()));
        }
    }
    entries
}

/// The external crates of `[workspace.dependencies]` (those without a `path`).
fn external_workspace_dependencies() -> Vec<String> {
    let manifest = read(&project_root().join("Cargo.toml"));
    section_entries(&manifest, "[workspace.dependencies]")
        .into_iter()
        .filter(|(_, spec)| !spec.contains("path ="))
        .map(|(name, _)| name)
        .collect()
}

#[test]
fn every_crate_has_a_section_in_the_architecture_document() {
    let architecture = read(&project_root().join("docs/ARCHITECTURE.md"));
    let missing: Vec<String> = crate_dirs()
        .iter()
        .map(|dir| {
            format!(
                "### `crates/{}`",
                dir.file_name().unwrap().to_string_lossy()
            )
        })
        .filter(|heading| !architecture.contains(heading.as_str()))
        .collect();
    assert!(
        missing.is_empty(),
        "docs/ARCHITECTURE.md lacks the sections {missing:?}"
    );
}

#[test]
fn every_dependency_is_explained_in_the_architecture_document() {
    let architecture = read(&project_root().join("docs/ARCHITECTURE.md"));
    let missing: Vec<String> = external_workspace_dependencies()
        .into_iter()
        .filter(|name| !architecture.contains(&format!("`{name}`")))
        .collect();
    assert!(
        missing.is_empty(),
        "docs/ARCHITECTURE.md does not explain the dependencies {missing:?}"
    );
}

#[test]
fn every_crate_root_starts_with_an_overview() {
    let mut roots: Vec<PathBuf> = crate_dirs()
        .iter()
        .flat_map(|dir| [dir.join("src/lib.rs"), dir.join("src/main.rs")])
        .collect();
    roots.push(project_root().join("xtask/src/main.rs"));
    let missing: Vec<String> = roots
        .iter()
        .filter(|path| path.is_file() && !read(path).trim_start().starts_with("//!"))
        .map(|path| path.display().to_string())
        .collect();
    assert!(
        missing.is_empty(),
        "crate roots without a `//!` overview: {missing:?}"
    );
}

#[test]
fn no_stubs_are_left_in_the_code() {
    let mut files = Vec::new();
    rust_files(&project_root().join("crates"), &mut files);
    rust_files(&project_root().join("xtask"), &mut files);
    let stubs = [concat!("todo", "!("), concat!("unimplemented", "!(")];
    let offenders: Vec<String> = files
        .iter()
        .filter(|path| {
            let text = read(path);
            stubs.iter().any(|stub| text.contains(stub))
        })
        .map(|path| path.display().to_string())
        .collect();
    assert!(offenders.is_empty(), "stubs left in {offenders:?}");
}

/// xtask only orchestrates; the evaluation lives in `crates/palc-eval`.
const XTASK_LINE_BUDGET: usize = 400;

#[test]
fn xtask_stays_within_its_line_budget() {
    let mut files = Vec::new();
    rust_files(&project_root().join("xtask/src"), &mut files);
    let lines: usize = files.iter().map(|path| read(path).lines().count()).sum();
    assert!(
        lines < XTASK_LINE_BUDGET,
        "xtask/src has {lines} lines, over its budget of {XTASK_LINE_BUDGET}: \
         move computation into a product crate (the evaluation lives in crates/palc-eval)"
    );
}

/// The `[dependencies]` (not dev-dependencies) of a crate's manifest, by name.
fn dependencies(manifest: &Path) -> Vec<String> {
    section_entries(&read(manifest), "[dependencies]")
        .into_iter()
        .map(|(name, _)| name)
        .collect()
}

#[test]
fn only_binaries_depend_on_the_evaluation() {
    let offenders: Vec<String> = crate_dirs()
        .iter()
        .filter(|dir| !dir.ends_with("palc-cli") && !dir.ends_with("palc-eval"))
        .filter(|dir| {
            dependencies(&dir.join("Cargo.toml"))
                .iter()
                .any(|d| d == "palc-eval")
        })
        .map(|dir| dir.display().to_string())
        .collect();
    assert!(
        offenders.is_empty(),
        "library crates that depend on palc-eval (only palc-cli may): {offenders:?}"
    );
}

#[test]
fn the_zone_filter_and_the_planner_depend_on_no_other_palc_crate() {
    for name in ["palc-zone-filter", "palc-planner"] {
        let manifest = project_root().join("crates").join(name).join("Cargo.toml");
        let palc: Vec<String> = dependencies(&manifest)
            .into_iter()
            .filter(|d| d.starts_with("palc-"))
            .collect();
        assert!(palc.is_empty(), "{name} depends on {palc:?}");
    }
}

/// Library crates never panic on input: clippy refuses `unwrap`/`expect` outside tests.
#[test]
fn library_crates_lint_unwrap_and_expect() {
    let lint = "#![cfg_attr(not(test), warn(clippy::unwrap_used, clippy::expect_used))]";
    let missing: Vec<String> = crate_dirs()
        .iter()
        .map(|dir| dir.join("src/lib.rs"))
        .filter(|lib| lib.is_file() && !read(lib).contains(lint))
        .map(|lib| lib.display().to_string())
        .collect();
    assert!(
        missing.is_empty(),
        "library crates without `{lint}`: {missing:?}"
    );
}

/// Every output file goes through `palc_aggregator::output` (atomic, checked).
#[test]
fn outputs_are_written_only_through_the_output_module() {
    let mut files = Vec::new();
    rust_files(&project_root().join("crates"), &mut files);
    let writers = [
        "File::create(",
        "fs::write(",
        "Writer::from_path(",
        "OpenOptions::new(",
    ];
    let offenders: Vec<String> = files
        .iter()
        .filter(|path| path.components().any(|c| c.as_os_str() == "src"))
        .filter(|path| !path.ends_with("palc-aggregator/src/output.rs"))
        .filter(|path| writers.iter().any(|w| read(path).contains(w)))
        .map(|path| path.display().to_string())
        .collect();
    assert!(
        offenders.is_empty(),
        "files that write outputs by hand (use palc_aggregator::output): {offenders:?}"
    );
}
