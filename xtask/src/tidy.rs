//! Repository hygiene, checked as ordinary tests (`cargo test -p xtask`).
//!
//! Each test reads files of the workspace and names what is out of place, so
//! that the documents stay true as the code changes: the architecture document's
//! sections, dependency rows, dependency rules and code names, the docs' line
//! length, every module's overview, and no import circle between a crate's modules.

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

/// Every module file (each `.rs` under `crates/*/src` and `xtask/src`, roots included)
/// starts with a `//!` overview of what it is for.
#[test]
fn every_module_starts_with_an_overview() {
    let mut files = Vec::new();
    for dir in crate_dirs() {
        rust_files(&dir.join("src"), &mut files);
    }
    rust_files(&project_root().join("xtask/src"), &mut files);
    let missing: Vec<String> = files
        .iter()
        .filter(|path| !read(path).trim_start().starts_with("//!"))
        .map(|path| path.display().to_string())
        .collect();
    assert!(
        missing.is_empty(),
        "modules without a `//!` overview: {missing:?}"
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
/// The budget counts the tasks: these hygiene tests (`tidy.rs`, built only for
/// tests) are not part of what `cargo xtask` runs. The real-browser test's
/// Chromium install raised it from 400.
const XTASK_LINE_BUDGET: usize = 430;

#[test]
fn xtask_stays_within_its_line_budget() {
    let mut files = Vec::new();
    rust_files(&project_root().join("xtask/src"), &mut files);
    files.retain(|path| !path.ends_with("tidy.rs"));
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
        // The front ends: the command line and the Python package.
        .filter(|dir| {
            !["palc-cli", "palc-py", "palc-eval"]
                .iter()
                .any(|d| dir.ends_with(d))
        })
        .filter(|dir| {
            dependencies(&dir.join("Cargo.toml"))
                .iter()
                .any(|d| d == "palc-eval")
        })
        .map(|dir| dir.display().to_string())
        .collect();
    assert!(
        offenders.is_empty(),
        "library crates that depend on palc-eval (only palc-cli and palc-py may): {offenders:?}"
    );
}

/// The dependency rules docs/ARCHITECTURE.md states, as (crate, the palc crates
/// it may depend on, whether the crate must exist). Only `[dependencies]` count.
const DEPENDENCY_RULES: &[(&str, &[&str], bool)] = &[
    ("palc-traffic", &[], true),
    ("palc-zone-filter", &[], true),
    ("palc-planner", &[], true),
    ("palc-commonroad", &[], true),
    (
        "palc-aggregator",
        &["palc-zone-filter", "palc-planner"],
        true,
    ),
    ("palc-user", &["palc-planner", "palc-traffic"], true),
    (
        "palc-harness",
        &[
            "palc-traffic",
            "palc-zone-filter",
            "palc-planner",
            "palc-aggregator",
            "palc-user",
        ],
        true,
    ),
    (
        "palc-drive",
        &[
            "palc-traffic",
            "palc-planner",
            "palc-aggregator",
            "palc-harness",
        ],
        true,
    ),
];

#[test]
fn every_crate_depends_only_on_the_palc_crates_the_architecture_allows() {
    let mut broken = Vec::new();
    for (name, allowed, required) in DEPENDENCY_RULES {
        let manifest = project_root().join("crates").join(name).join("Cargo.toml");
        if !manifest.is_file() {
            assert!(!required, "{} is missing", manifest.display());
            continue;
        }
        let extra: Vec<String> = dependencies(&manifest)
            .into_iter()
            .filter(|d| d.starts_with("palc-") && !allowed.contains(&d.as_str()))
            .collect();
        if !extra.is_empty() {
            broken.push(format!(
                "{name} depends on {extra:?} (allowed: {allowed:?})"
            ));
        }
    }
    assert!(broken.is_empty(), "dependency rules broken: {broken:?}");
}

#[test]
fn xtask_depends_only_on_anyhow() {
    let deps = dependencies(&project_root().join("xtask/Cargo.toml"));
    assert_eq!(
        deps,
        ["anyhow"],
        "xtask's [dependencies] must be anyhow alone"
    );
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
        "SVGBackend::new(",
        "BitMapBackend::new(",
        "BitMapBackend::gif(",
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

/// The longest line a document under `docs/` may have, in characters.
const DOCS_LINE_LIMIT: usize = 200;

fn markdown_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let path = entry.path();
        if path.is_dir() {
            markdown_files(&path, out);
        } else if path.extension().is_some_and(|ext| ext == "md") {
            out.push(path);
        }
    }
}

/// Every line of every `docs/**/*.md` has at most 200 characters (not bytes).
#[test]
fn no_docs_line_is_longer_than_200_characters() {
    let mut files = Vec::new();
    markdown_files(&project_root().join("docs"), &mut files);
    let mut long = Vec::new();
    for path in &files {
        for (number, line) in read(path).lines().enumerate() {
            let chars = line.chars().count();
            if chars > DOCS_LINE_LIMIT {
                long.push(format!("{}:{} ({chars})", path.display(), number + 1));
            }
        }
    }
    assert!(
        long.is_empty(),
        "docs lines over {DOCS_LINE_LIMIT} characters (wrap them, one sentence a line): {long:?}"
    );
}

/// The text of every code span (`` `...` ``, any number of backticks) of a Markdown text.
fn code_spans(text: &str) -> Vec<String> {
    let mut spans = Vec::new();
    let mut rest = text;
    while let Some(start) = rest.find('`') {
        let ticks = rest[start..].len() - rest[start..].trim_start_matches('`').len();
        let body = &rest[start + ticks..];
        let fence = "`".repeat(ticks);
        let Some(end) = body.find(fence.as_str()) else {
            break;
        };
        spans.push(body[..end].trim().to_owned());
        rest = &body[end + ticks..];
    }
    spans
}

fn is_identifier(word: &str) -> bool {
    let mut chars = word.chars();
    chars
        .next()
        .is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
        && chars.all(|c| c.is_ascii_alphanumeric() || c == '_')
}

/// What a code span of a document claims exists in the workspace, if anything.
#[derive(Debug, PartialEq)]
enum CodeName {
    /// Identifiers that must each occur in the Rust sources.
    Identifiers(Vec<String>),
    /// A `.rs` file that must exist (a path suffix of one).
    RustFile(String),
    /// A path under `configs/` that must exist.
    ConfigPath(String),
}

/// The rule: a span names code when it is (after an optional `[...]` around a TOML table)
/// - a path with `::` at its start (`Scene::step(dt)` checks `Scene` and `step`),
/// - a CamelCase type name (`LearningLoop`) or a SCREAMING_CASE constant (`MAX_POSITION`),
/// - a snake_case name with an underscore (`learn_from_lesson`),
/// - a dotted config key (`planning.safety.enforce`: its last key is a Rust field),
/// - a `.rs` file (`src/tidy.rs`) or a path under `configs/`.
///
/// Anything else (math, units, commands, values, globs) is not checked.
fn code_name(span: &str) -> Option<CodeName> {
    if span.contains('*') || (span.contains(' ') && !span.contains("::")) {
        return None;
    }
    if span.starts_with("configs/") {
        return Some(CodeName::ConfigPath(span.to_owned()));
    }
    if span.ends_with(".rs") {
        return Some(CodeName::RustFile(span.to_owned()));
    }
    let lead_end = span
        .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_' || c == ':'))
        .unwrap_or(span.len());
    let lead = span[..lead_end].trim_end_matches(':');
    if lead.contains("::") {
        let segments: Vec<String> = lead.split("::").map(str::to_owned).collect();
        return segments
            .iter()
            .all(|s| is_identifier(s))
            .then_some(CodeName::Identifiers(segments));
    }
    let table = span
        .strip_prefix('[')
        .and_then(|s| s.strip_suffix(']'))
        .unwrap_or(span);
    if table.contains('.') {
        let keys: Vec<&str> = table.split('.').collect();
        let lowercase = |k: &&str| is_identifier(k) && !k.chars().any(|c| c.is_ascii_uppercase());
        let extensions = ["json", "csv", "toml", "md", "svg", "png", "tmp"];
        let last = keys.last().copied().unwrap_or_default();
        return (keys.iter().all(lowercase) && !extensions.contains(&last))
            .then(|| CodeName::Identifiers(vec![last.to_owned()]));
    }
    if !is_identifier(span) {
        return None;
    }
    let has_lower = span.chars().any(|c| c.is_ascii_lowercase());
    let has_upper = span.chars().any(|c| c.is_ascii_uppercase());
    let camel =
        span.starts_with(|c: char| c.is_ascii_uppercase()) && has_lower && !span.contains('_');
    let screaming = has_upper && !has_lower && span.contains('_');
    let snake = has_lower && !has_upper && span.contains('_');
    (camel || screaming || snake).then(|| CodeName::Identifiers(vec![span.to_owned()]))
}

/// Every identifier of the Rust sources of `crates/` and `xtask/` and of the Python
/// package's sources (`python/palc/*.py`, the simulator bridges), and every `.rs` path.
fn rust_names() -> (std::collections::BTreeSet<String>, Vec<String>) {
    let mut files = Vec::new();
    rust_files(&project_root().join("crates"), &mut files);
    rust_files(&project_root().join("xtask"), &mut files);
    let python = fs::read_dir(project_root().join("python/palc"))
        .into_iter()
        .flatten();
    let python: Vec<PathBuf> = (python.flatten().map(|entry| entry.path()))
        .filter(|path| path.extension().is_some_and(|ext| ext == "py"))
        .collect();
    let mut identifiers = std::collections::BTreeSet::new();
    // This file's own examples do not count as code.
    for path in (files.iter().chain(&python)).filter(|path| !path.ends_with("tidy.rs")) {
        for word in read(path).split(|c: char| !(c.is_ascii_alphanumeric() || c == '_')) {
            if is_identifier(word) {
                identifiers.insert(word.to_owned());
            }
        }
    }
    let paths = files
        .iter()
        .map(|p| p.to_string_lossy().replace('\\', "/"))
        .collect();
    (identifiers, paths)
}

/// Every code name docs/ARCHITECTURE.md and docs/paper-mapping.md cite exists, by the
/// rule of [`code_name`]: its identifiers occur somewhere in the Rust sources, its `.rs`
/// file ends some source path, its `configs/` path exists.
#[test]
fn every_code_name_the_docs_cite_exists() {
    let (identifiers, paths) = rust_names();
    let mut missing = Vec::new();
    for doc in ["docs/ARCHITECTURE.md", "docs/paper-mapping.md"] {
        for span in code_spans(&read(&project_root().join(doc))) {
            let found = match code_name(&span) {
                None => true,
                Some(CodeName::Identifiers(names)) => names.iter().all(|n| identifiers.contains(n)),
                Some(CodeName::RustFile(file)) => {
                    paths.iter().any(|p| p.ends_with(&format!("/{file}")))
                }
                Some(CodeName::ConfigPath(path)) => project_root().join(path).exists(),
            };
            if !found {
                missing.push(format!("{doc}: `{span}`"));
            }
        }
    }
    missing.dedup();
    assert!(
        missing.is_empty(),
        "code names the docs cite but the code lacks: {missing:?}"
    );
}

#[test]
fn code_names_follow_the_documented_rule() {
    let ids = |names: &[&str]| {
        Some(CodeName::Identifiers(
            names.iter().map(|n| (*n).to_owned()).collect(),
        ))
    };
    assert_eq!(
        code_name("Scene::step(dt, EgoState)"),
        ids(&["Scene", "step"])
    );
    assert_eq!(code_name("LearningLoop"), ids(&["LearningLoop"]));
    assert_eq!(code_name("MAX_POSITION"), ids(&["MAX_POSITION"]));
    assert_eq!(code_name("learn_from_lesson"), ids(&["learn_from_lesson"]));
    assert_eq!(code_name("planning.safety.enforce"), ids(&["enforce"]));
    assert_eq!(code_name("[user.family]"), ids(&["family"]));
    assert_eq!(
        code_name("src/tidy.rs"),
        Some(CodeName::RustFile("src/tidy.rs".into()))
    );
    for not_code in [
        "w1",
        "l = 0",
        "runs.json",
        "K",
        "PSD",
        "*_report.rs",
        "--quick",
    ] {
        assert_eq!(code_name(not_code), None, "{not_code}");
    }
    assert_eq!(
        code_spans("a `b` and `` `[c]` `` then ```d```"),
        ["b", "`[c]`", "d"]
    );
}

/// The first path segment after each `crate::` of a Rust text (line comments skipped),
/// with grouped imports (`use crate::{a, b::c}`, over several lines too) giving each
/// of their first segments. `$crate::` and `super::` paths are not read.
fn crate_paths(text: &str) -> Vec<String> {
    let code: String = text
        .lines()
        .map(|line| line.split("//").next().unwrap_or_default())
        .collect::<Vec<_>>()
        .join("\n");
    let mut firsts = Vec::new();
    let mut rest = code.as_str();
    while let Some(at) = rest.find("crate::") {
        let before = rest[..at].chars().next_back();
        let after = &rest[at + "crate::".len()..];
        rest = after;
        if before.is_some_and(|c| c.is_ascii_alphanumeric() || c == '_' || c == '$') {
            continue;
        }
        let Some(group) = after.strip_prefix('{') else {
            let end = after
                .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
                .unwrap_or(after.len());
            firsts.push(after[..end].to_owned());
            continue;
        };
        let (mut depth, mut item_start, mut word) = (0, true, String::new());
        for c in group.chars() {
            if c.is_ascii_alphanumeric() || c == '_' {
                if item_start {
                    word.push(c);
                }
                continue;
            }
            if !word.is_empty() {
                firsts.push(std::mem::take(&mut word));
                item_start = false;
            }
            match c {
                '{' => depth += 1,
                '}' if depth == 0 => break,
                '}' => depth -= 1,
                ',' if depth == 0 => item_start = true,
                c if c.is_whitespace() => {}
                _ => item_start = false,
            }
        }
    }
    firsts.retain(|w| !w.is_empty() && w != "self");
    firsts
}

/// A Rust text without its `#[cfg(test)]` items (a braced item to its closing brace,
/// another to its `;`): tests may reach across modules without making a circle.
fn without_test_code(text: &str) -> String {
    let mut kept = Vec::new();
    let (mut skipping, mut depth, mut opened) = (false, 0_i32, false);
    for line in text.lines() {
        let code = line.split("//").next().unwrap_or_default();
        if !skipping && code.trim_start().starts_with("#[cfg(test)]") {
            (skipping, depth, opened) = (true, 0, false);
            continue;
        }
        if !skipping {
            kept.push(line);
            continue;
        }
        if !opened && code.trim_start().starts_with("#[") {
            continue;
        }
        for c in code.chars() {
            match c {
                '{' => (depth, opened) = (depth + 1, true),
                '}' => depth -= 1,
                _ => {}
            }
        }
        if (opened && depth <= 0) || (!opened && code.trim_end().ends_with(';')) {
            skipping = false;
        }
    }
    kept.join("\n")
}

/// The modules a crate root declares for tests only (`#[cfg(test)] mod fuzz;`).
fn test_only_modules(root: &str) -> Vec<String> {
    let lines: Vec<&str> = root.lines().map(str::trim).collect();
    lines
        .windows(2)
        .filter(|pair| pair[0].starts_with("#[cfg(test)]"))
        .filter_map(|pair| pair[1].strip_prefix("mod ")?.strip_suffix(';'))
        .map(str::to_owned)
        .collect()
}

/// The top-level module a file under `src/` belongs to (`src/a.rs`, `src/a/b.rs`: `a`),
/// or `None` for the crate root (`lib.rs`, `main.rs`).
fn top_module(src: &Path, file: &Path) -> Option<String> {
    let relative = file.strip_prefix(src).ok()?;
    let mut parts = relative.components();
    let first = parts.next()?.as_os_str().to_string_lossy().into_owned();
    if parts.next().is_some() {
        return Some(first);
    }
    let stem = first.strip_suffix(".rs")?;
    (stem != "lib" && stem != "main").then(|| stem.to_owned())
}

/// The root's names that a `use`/`pub use` of the root takes from a top-level module
/// (`pub use config::{LearnConfig, X}`: `LearnConfig` and `X` are `config`'s).
fn root_reexports(root: &str, modules: &[String]) -> Vec<(String, String)> {
    let mut names = Vec::new();
    let text: String = root
        .lines()
        .map(|l| l.split("//").next().unwrap_or_default())
        .collect::<Vec<_>>()
        .join("\n");
    for statement in text.split(';') {
        let Some(at) = statement.find("use ") else {
            continue;
        };
        let path = statement[at + 4..].trim().trim_start_matches("crate::");
        let Some((module, items)) = path.split_once("::") else {
            continue;
        };
        if !modules.iter().any(|m| m == module) {
            continue;
        }
        for item in items.split([',', '{', '}']) {
            let name = item.split(" as ").last().unwrap_or_default().trim();
            let name = name.rsplit("::").next().unwrap_or_default();
            if is_identifier(name) && name != "self" {
                names.push((name.to_owned(), module.to_owned()));
            }
        }
    }
    names
}

/// The import graph between the top-level modules of a crate's `src/`, each edge with a
/// file that makes it.
fn module_graph(src: &Path) -> std::collections::BTreeMap<(String, String), String> {
    let mut files = Vec::new();
    rust_files(src, &mut files);
    files.sort();
    let mut modules: Vec<String> = files.iter().filter_map(|f| top_module(src, f)).collect();
    modules.sort();
    modules.dedup();
    let mut owner: std::collections::BTreeMap<String, String> =
        modules.iter().map(|m| (m.clone(), m.clone())).collect();
    let mut tests_only = Vec::new();
    for root in ["lib.rs", "main.rs"] {
        if src.join(root).is_file() {
            let text = read(&src.join(root));
            tests_only.extend(test_only_modules(&text));
            for (name, module) in root_reexports(&without_test_code(&text), &modules) {
                owner.entry(name).or_insert(module);
            }
        }
    }
    let mut edges = std::collections::BTreeMap::new();
    for file in &files {
        let Some(from) = top_module(src, file).filter(|m| !tests_only.contains(m)) else {
            continue;
        };
        for first in crate_paths(&without_test_code(&read(file))) {
            if let Some(to) = owner.get(&first).filter(|to| **to != from) {
                edges.entry((from.clone(), to.clone())).or_insert_with(|| {
                    file.strip_prefix(src).unwrap_or(file).display().to_string()
                });
            }
        }
    }
    edges
}

/// The strongly connected components with more than one node (Tarjan's algorithm).
fn cycles(edges: &[(String, String)]) -> Vec<Vec<String>> {
    struct Tarjan<'a> {
        edges: &'a [(String, String)],
        index: std::collections::BTreeMap<&'a str, (usize, usize)>,
        stack: Vec<&'a str>,
        found: Vec<Vec<String>>,
    }
    impl<'a> Tarjan<'a> {
        fn lower(&mut self, node: &str, low: usize) {
            if let Some(entry) = self.index.get_mut(node) {
                entry.1 = low;
            }
        }

        fn visit(&mut self, node: &'a str) {
            let n = self.index.len();
            self.index.insert(node, (n, n));
            self.stack.push(node);
            for (from, to) in self.edges {
                if from != node {
                    continue;
                }
                if !self.index.contains_key(to.as_str()) {
                    self.visit(to);
                    let low = self.index[to.as_str()].1.min(self.index[node].1);
                    self.lower(node, low);
                } else if self.stack.contains(&to.as_str()) {
                    let low = self.index[to.as_str()].0.min(self.index[node].1);
                    self.lower(node, low);
                }
            }
            let (number, low) = self.index[node];
            if number == low {
                let at = self.stack.iter().rposition(|n| *n == node).unwrap_or(0);
                let mut component: Vec<String> =
                    self.stack.drain(at..).map(str::to_owned).collect();
                if component.len() > 1 {
                    component.sort();
                    self.found.push(component);
                }
            }
        }
    }
    let mut tarjan = Tarjan {
        edges,
        index: std::collections::BTreeMap::new(),
        stack: Vec::new(),
        found: Vec::new(),
    };
    for (from, _) in edges {
        if !tarjan.index.contains_key(from.as_str()) {
            tarjan.visit(from);
        }
    }
    tarjan.found.sort();
    tarjan.found
}

/// No crate's top-level modules import each other in a circle: `crate::` paths, grouped
/// imports and `pub use` count, a name the root re-exports counts as its module's, and
/// the root and test code (`#[cfg(test)]` items and modules) are not sources.
/// Prints every circle found, with a file that makes each of its edges.
#[test]
fn no_crate_has_an_import_circle_between_its_modules() {
    let mut report = Vec::new();
    let mut dirs = crate_dirs();
    dirs.push(project_root().join("xtask"));
    for dir in dirs {
        let graph = module_graph(&dir.join("src"));
        let edges: Vec<(String, String)> = graph.keys().cloned().collect();
        for component in cycles(&edges) {
            let inside: Vec<String> = graph
                .iter()
                .filter(|((a, b), _)| component.contains(a) && component.contains(b))
                .map(|((a, b), file)| format!("{a} -> {b} ({file})"))
                .collect();
            report.push(format!(
                "{}: {} [{}]",
                dir.file_name().unwrap_or_default().to_string_lossy(),
                component.join(", "),
                inside.join("; ")
            ));
        }
    }
    for line in &report {
        println!("import circle in {line}");
    }
    assert!(report.is_empty(), "import circles: {report:#?}");
}

#[test]
fn the_import_parser_reads_paths_groups_and_reexports() {
    let text = "use crate::{a, b::c, d::{e, f}, self};\n\
                pub use crate::g::h as i;\n\
                let x = crate::j::k();\n\
                // crate::comment\n\
                $crate::m!(); other_crate::n;\n\
                use crate::{\n    o::p,\n    q,\n};";
    assert_eq!(crate_paths(text), ["a", "b", "d", "g", "j", "o", "q"]);
    let stripped = without_test_code(
        "use crate::a;\n#[cfg(test)]\nmod tests {\n    use crate::b;\n    fn f() {}\n}\n\
         #[cfg(test)]\nuse crate::c;\nuse crate::d;",
    );
    assert_eq!(crate_paths(&stripped), ["a", "d"]);
    assert_eq!(
        test_only_modules("#[cfg(test)]\nmod fuzz;\nmod parse;"),
        ["fuzz"]
    );
    let exports = root_reexports(
        "pub use config::{LearnConfig, Max as Limit};\nmod config;",
        &["config".to_owned()],
    );
    assert_eq!(
        exports,
        [
            ("LearnConfig".to_owned(), "config".to_owned()),
            ("Limit".to_owned(), "config".to_owned())
        ]
    );
    let edge = |a: &str, b: &str| (a.to_owned(), b.to_owned());
    let graph = [
        edge("a", "b"),
        edge("b", "c"),
        edge("c", "a"),
        edge("c", "d"),
        edge("d", "e"),
        edge("e", "d"),
    ];
    assert_eq!(cycles(&graph), [vec!["a", "b", "c"], vec!["d", "e"]]);
}
