//! What every section of REPORT.md is: a [`Section`] with a title that writes
//! its text into an [`Out`], with the long lists it writes as CSV files beside
//! REPORT.md ([`CsvTable`]) instead of in the text.

use std::fmt;

use palc_harness::Method;

use crate::config::UserKind;
use crate::harness_runs::ExampleTrace;
use crate::manifest::Manifest;
use crate::targets::{TargetId, Verdict, target};
use crate::views::{FigureFile, Indexed};

/// Everything the report is made of.
pub struct ReportInput<'a> {
    /// Every run, in plan order.
    pub rows: &'a [crate::RunRow],
    /// Methods in report order.
    pub methods: &'a [Method],
    /// The paper's user kinds (no family), in report order.
    pub users: &'a [String],
    /// Every user kind of the selection.
    pub user_kinds: &'a [UserKind],
    /// The example run, or why it is missing.
    pub example: Result<&'a ExampleTrace, String>,
    /// The figures written.
    pub figures: &'a [FigureFile],
    /// The manifest.
    pub manifest: &'a Manifest,
    /// The ablation ladder's rungs and user kinds (empty without ablation runs).
    pub ablation: (&'a [crate::ablation::Rung], &'a [String]),
    /// The recorded user kinds' drivers.
    pub recorded: &'a [crate::recorded_drivers::RecordedDrivers],
    /// The experiments none of whose runs ran.
    pub idle: &'a [crate::IdleExperiment],
}

/// The report's input with its rows indexed once: what every section reads.
pub struct Results<'a> {
    /// The input.
    pub input: &'a ReportInput<'a>,
    /// The rows, by experiment, method and user kind.
    pub index: Indexed<'a>,
}

impl<'a> Results<'a> {
    /// Indexes the input's rows.
    pub fn new(input: &'a ReportInput<'a>) -> Results<'a> {
        Results {
            input,
            index: Indexed::new(input.rows),
        }
    }

    /// The methods in report order.
    pub fn methods(&self) -> &'a [Method] {
        self.input.methods
    }

    /// The takeover cap (the largest of the runs).
    pub fn cap(&self) -> usize {
        self.input.rows.iter().map(|r| r.cap).max().unwrap_or(0)
    }
}

/// One section of REPORT.md.
pub trait Section: Sync {
    /// The section's heading, without the `## `.
    fn title(&self) -> &'static str;

    /// Whether the runs have anything for this section; a section that does not
    /// apply writes nothing, not even its heading.
    fn applies(&self, _results: &Results) -> bool {
        true
    }

    /// Writes the section's text after its heading, and its long lists as CSV
    /// tables.
    fn render(&self, results: &Results, out: &mut Out) -> fmt::Result;
}

/// A long list written as a CSV file beside REPORT.md.
#[derive(Debug, Clone, PartialEq)]
pub struct CsvTable {
    /// File name, in the output directory.
    pub file: &'static str,
    /// Column names.
    pub header: &'static [&'static str],
    /// One record per line, as many cells as columns.
    pub rows: Vec<Vec<String>>,
}

/// What the sections write: the report's text and the CSV tables.
#[derive(Debug, Default, Clone, PartialEq)]
pub struct Out {
    /// The text of REPORT.md.
    pub text: String,
    /// The CSV files beside it.
    pub tables: Vec<CsvTable>,
}

impl Out {
    /// Adds a CSV table; its rows are added to a table of the same file.
    pub fn table(&mut self, file: &'static str, header: &'static [&'static str]) -> &mut CsvTable {
        let at = match self.tables.iter().position(|t| t.file == file) {
            Some(at) => at,
            None => {
                self.tables.push(CsvTable {
                    file,
                    header,
                    rows: Vec::new(),
                });
                self.tables.len() - 1
            }
        };
        &mut self.tables[at]
    }
}

impl fmt::Write for Out {
    fn write_str(&mut self, s: &str) -> fmt::Result {
        self.text.push_str(s);
        Ok(())
    }
}

/// A template with every `{name}` replaced by its value; a template's text
/// holds prose only, its numbers come from the code.
pub fn fill(template: &str, values: &[(&str, String)]) -> String {
    let mut text = template.trim_end().to_owned();
    for (name, value) in values {
        text = text.replace(&format!("{{{name}}}"), value);
    }
    text
}

/// Each target of `ids` stated once per method, over every user kind, as
/// bullet lines (`Target::state_cases`); a target with nothing measured for a
/// method is left out.
pub fn state_targets(out: &mut Out, results: &Results, ids: &[TargetId]) -> fmt::Result {
    use fmt::Write as _;
    for target in ids.iter().map(|&id| target(id)) {
        for &method in results.methods() {
            let cases = target.cases(&results.index, method, results.input.user_kinds);
            if target.judge(&cases) == Verdict::NotMeasured {
                continue;
            }
            let who = format!("`{}`, each user kind", method.name());
            writeln!(out, "- {}", target.state_cases(&who, &cases))?;
        }
    }
    Ok(())
}

/// A markdown table's header line and separator.
pub fn header(out: &mut Out, columns: &[&str]) -> fmt::Result {
    use fmt::Write as _;
    writeln!(out, "| {} |", columns.join(" | "))?;
    writeln!(out, "|{}", " --- |".repeat(columns.len()))
}
