//! REPORT.md's figures: every figure written, its caption and a link to its PNG.

use std::fmt::{self, Write as _};

use super::section::{Out, Results, Section};

/// The figures section.
pub struct Figures;

impl Section for Figures {
    fn title(&self) -> &'static str {
        "Figures"
    }

    fn applies(&self, results: &Results) -> bool {
        !results.input.figures.is_empty()
    }

    fn render(&self, results: &Results, out: &mut Out) -> fmt::Result {
        for figure in results.input.figures {
            writeln!(
                out,
                "{} ([PNG]({}.png))\n![{}]({}.svg)\n",
                figure.caption, figure.stem, figure.stem, figure.stem
            )?;
        }
        Ok(())
    }
}
