//! LaTeX → MathML for the report and the studio, by `pulldown-latex`:
//! browsers draw MathML natively, so formulas need no script, font server
//! or network.

use pulldown_latex::config::DisplayMode;
use pulldown_latex::{push_mathml, Parser, RenderConfig, Storage};

/// The MathML of one formula (display style when `block`). LaTeX the parser
/// does not know is drawn in red inside the formula, never dropped; the
/// LaTeX source rides along as the annotation, for copying.
pub fn mathml(latex: &str, block: bool) -> String {
    let storage = Storage::new();
    let parser = Parser::new(latex, &storage);
    let config = RenderConfig {
        display_mode: if block {
            DisplayMode::Block
        } else {
            DisplayMode::Inline
        },
        annotation: Some(latex),
        ..RenderConfig::default()
    };
    let mut out = String::new();
    match push_mathml(&mut out, parser, config) {
        Ok(()) => out,
        // Writing into a String cannot fail; keep the source visible anyway.
        Err(_) => format!("<code>{}</code>", crate::report::escape(latex)),
    }
}
