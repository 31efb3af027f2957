//! REPORT.md's lessons that could not be learned: per method, how many, of how
//! many takeovers, in how many runs; their causes grouped by kind (the message
//! up to its details, such as the steps of an infeasible plan), each with one
//! full example, go to [`FILE`].

use std::fmt::{self, Write as _};

use palc_harness::Method;

use super::section::{Out, Results, Section, header};

/// The CSV file of the causes.
pub const FILE: &str = "lessons-not-learned.csv";
const COLUMNS: &[&str] = &["method", "cause", "lessons", "example"];

/// The lessons section.
pub struct Lessons;

impl Section for Lessons {
    fn title(&self) -> &'static str {
        "Lessons that could not be learned"
    }

    fn render(&self, results: &Results, out: &mut Out) -> fmt::Result {
        writeln!(
            out,
            "A lesson that cannot be learned leaves the experience unchanged: the next lane change \
             repeats the plan, and the cap counts it. The causes, grouped by kind with one example \
             each, are in `{FILE}`.\n"
        )?;
        header(
            out,
            &[
                "method",
                "lessons not learned",
                "of takeovers",
                "runs with one",
            ],
        )?;
        let mut causes: Vec<(Method, &str, usize, &str)> = Vec::new();
        for &method in results.methods() {
            let rows = results.index.of_method(method);
            let errors: Vec<&str> = (rows.iter())
                .flat_map(|r| {
                    r.iterations
                        .iter()
                        .filter_map(|it| it.learning_error.as_deref())
                })
                .collect();
            let takeovers: usize = (rows.iter())
                .map(|r| r.iterations.iter().filter(|it| it.takeover).count())
                .sum();
            let runs = (rows.iter())
                .filter(|r| r.iterations.iter().any(|it| it.learning_error.is_some()))
                .count();
            writeln!(
                out,
                "| {} | {} | {takeovers} | {runs} of {} |",
                method.name(),
                errors.len(),
                rows.len()
            )?;
            for error in errors {
                let kind = cause_kind(error);
                match causes
                    .iter_mut()
                    .find(|(m, k, ..)| *m == method && *k == kind)
                {
                    Some((_, _, n, _)) => *n += 1,
                    None => causes.push((method, kind, 1, error)),
                }
            }
        }
        writeln!(out)?;
        let table = out.table(FILE, COLUMNS);
        for (method, kind, n, example) in causes {
            table.rows.push(vec![
                method.name().to_owned(),
                kind.to_owned(),
                n.to_string(),
                example.to_owned(),
            ]);
        }
        Ok(())
    }
}

/// The kind of a learning error: its first two clauses (`what failed: why`),
/// without the details that follow.
fn cause_kind(error: &str) -> &str {
    match error.match_indices(": ").nth(1) {
        Some((end, _)) => &error[..end],
        None => error,
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn a_learning_error_is_grouped_by_its_first_two_clauses() {
        assert_eq!(
            super::cause_kind("expert could not be planned: problem is infeasible: steps 3..=4"),
            "expert could not be planned: problem is infeasible"
        );
        assert_eq!(super::cause_kind("zone: bad"), "zone: bad");
    }
}
