//! REPORT.md: one screen of verdicts first (the paper's claims, palc's targets,
//! the figures that matter), then the details, one [`Section`] each, in the
//! order of [`SECTIONS`]. Long lists go to CSV files beside REPORT.md
//! ([`TABLE_FILES`]); long prose lives in `templates/*.md`.
//!
//! Adding an experiment's section is one module that implements [`Section`]
//! and one line in [`SECTIONS`].

use std::fmt::Write as _;

mod ablation;
mod claims;
mod closed_loop;
mod drive;
mod example;
mod families;
mod figures;
mod front;
mod lessons;
mod manifest;
mod outside;
mod recorded;
mod refusals;
mod safety;
mod section;
mod summary;
mod timing;
mod transfer;
mod user_kinds;

pub use section::{CsvTable, Out, ReportInput, Results, Section, fill};

/// Every section, in report order.
pub const SECTIONS: &[&dyn Section] = &[
    &summary::Summary,
    &user_kinds::UserKinds,
    &families::Families,
    &recorded::Recorded,
    &transfer::Transfer,
    &drive::Drive,
    &outside::Outside,
    &ablation::Ablation,
    &safety::Safety,
    &closed_loop::ClosedLoop,
    &timing::Timing,
    &refusals::Refusals,
    &lessons::Lessons,
    &example::Example,
    &claims::HowMeasured,
    &figures::Figures,
    &manifest::RunManifest,
];

/// Every CSV file a section may write beside REPORT.md: a file of an earlier
/// run that this one does not write is not carried over.
pub const TABLE_FILES: &[&str] = &[
    user_kinds::FILE,
    families::FILE,
    recorded::FILE,
    transfer::MATRIX_FILE,
    transfer::ACCUMULATION_FILE,
    ablation::FILE,
    lessons::FILE,
    outside::FILE,
];

/// Writes REPORT.md's text and the CSV tables beside it.
pub fn render(input: &ReportInput) -> Out {
    let results = Results::new(input);
    let mut out = Out::default();
    // Writing into a String cannot fail.
    let _ = write_all(&results, &mut out);
    out
}

fn write_all(results: &Results, out: &mut Out) -> std::fmt::Result {
    front::write(results, out)?;
    for section in SECTIONS {
        if section.applies(results) {
            writeln!(out, "## {}\n", section.title())?;
            section.render(results, out)?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use palc_harness::Method;

    use super::*;
    use crate::manifest::Manifest;
    use crate::runner::tests::synthetic_rows;

    fn manifest() -> Manifest {
        Manifest {
            palc_version: "0.1.0".into(),
            git_commit: None,
            git_dirty: None,
            config_sha256: "00".into(),
            config_path: "configs/reproduce.toml".into(),
            base_path: "configs/learn.toml".into(),
            quick: true,
            seeds: vec![1, 2],
            threads: 2,
            cores: 2,
            machine: "linux x86_64".into(),
            runs: 3,
            wall_s: 1.0,
        }
    }

    #[test]
    fn the_report_opens_with_the_verdicts_and_names_refusals() {
        let rows = synthetic_rows();
        let manifest = manifest();
        let methods = [Method::Paper, Method::Palc];
        let users = ["deterministic".to_owned(), "spread".to_owned()];
        let out = render(&ReportInput {
            rows: &rows,
            methods: &methods,
            users: &users,
            user_kinds: &[],
            example: Err("not run in this test".into()),
            figures: &[],
            manifest: &manifest,
            ablation: (&[], &[]),
            recorded: &[],
            idle: &[],
        });
        let report = &out.text;
        // The first screen: the claims and the targets, each with its verdict.
        let front = report.split("\n## ").next().unwrap();
        assert!(
            front.contains("| claim | paper | `paper` | `palc` | verdict |"),
            "{front}"
        );
        assert!(
            front.contains("| target | rule | `palc` | verdict |"),
            "{front}"
        );
        assert!(
            report
                .contains("| metric | paper's claim | `paper` method | `palc` method | verdict |")
        );
        assert!(report.contains("| mean takeovers to personalization (failures at 30) | 13.8 |"));
        // The synthetic paper method never personalizes: 30 everywhere, 117 % above 13.8.
        assert!(report.contains("paper: 117 % higher"), "{report}");
        assert!(report.contains("takeover reduction with experience"));
        assert!(report.contains("## Summary"));
        // Refusals are counted by kind and experiment, with one example each.
        assert!(report.contains("| kind | grid |"), "{report}");
        assert!(report.contains("| `standard-not-slower` |"), "{report}");
        assert!(report.contains("is not slower than the cautious user's (3.5 s)"));
        let refused = rows.iter().filter(|r| !r.status.counted()).count();
        assert!(report.contains(&format!("{refused} of {} runs were refused", rows.len())));
        assert!(report.contains("**This is the `--quick` subset**"));
        assert!(report.contains("## Lessons that could not be learned"));
        assert!(report.contains("## How each claim and target is measured"));
        // One paragraph after the run count, no stray line break or leading space.
        assert!(
            report.contains("grid runs per method. Deterministic users are the paper's set-up.\n")
        );
        assert!(!report.contains("\n "), "a line starts with a space");
        // The sensitivity tables are a CSV file beside the report.
        let sensitivity = out
            .tables
            .iter()
            .find(|t| t.file == user_kinds::FILE)
            .unwrap();
        assert!(
            sensitivity
                .rows
                .iter()
                .any(|r| r[2] == "style" && r[3] == "aggressive")
        );
        assert!(TABLE_FILES.iter().all(|f| f.ends_with(".csv")));
        for table in &out.tables {
            assert!(TABLE_FILES.contains(&table.file), "{}", table.file);
            assert!(table.rows.iter().all(|r| r.len() == table.header.len()));
        }
    }

    #[test]
    fn every_section_has_its_own_title() {
        for (i, section) in SECTIONS.iter().enumerate() {
            let title = section.title();
            assert!(!title.is_empty());
            assert!(
                !SECTIONS[..i].iter().any(|s| s.title() == title),
                "{title} twice"
            );
        }
    }
}
