//! REPORT.md's qualitative example (Fig. 6): the example run's lane changes and
//! takeovers against the paper's example.

use std::fmt::{self, Write as _};

use super::section::{Out, Results, Section};

/// The example section.
pub struct Example;

impl Section for Example {
    fn title(&self) -> &'static str {
        "Qualitative example (Fig. 6)"
    }

    fn render(&self, results: &Results, out: &mut Out) -> fmt::Result {
        match &results.input.example {
            Ok(trace) => {
                let takeovers = (trace.lane_changes.iter())
                    .filter(|lc| lc.takeover_step.is_some())
                    .count();
                writeln!(
                    out,
                    "{}: {} lane changes, {} with a takeover; {}. The paper's example personalizes an \
                     aggressive driver after 10 iterations.\n",
                    trace.label,
                    trace.lane_changes.len(),
                    takeovers,
                    if trace.personalized {
                        "personalized"
                    } else {
                        "not personalized within the cap"
                    }
                )
            }
            Err(reason) => writeln!(out, "The example run did not complete: {reason}\n"),
        }
    }
}
