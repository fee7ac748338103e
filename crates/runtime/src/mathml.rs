//! LaTeX → MathML for the report and the studio, by `pulldown-latex`:
//! browsers draw MathML natively, so formulas need no script, font server
//! or network.

use pulldown_latex::config::DisplayMode;
use pulldown_latex::{push_mathml, Parser, RenderConfig, Storage};

/// The MathML of one formula (display style when `block`). LaTeX the parser
/// does not know is drawn in red inside the formula, never dropped.
/// pulldown-latex 0.8 writes the relations `<` and `>` and an annotation's
/// text unescaped, so no annotation is asked for and the two relations are
/// escaped here.
pub fn mathml(latex: &str, block: bool) -> String {
    let latex = powers_of_functions(latex);
    let storage = Storage::new();
    let parser = Parser::new(&latex, &storage);
    let config = RenderConfig {
        display_mode: if block {
            DisplayMode::Block
        } else {
            DisplayMode::Inline
        },
        ..RenderConfig::default()
    };
    let mut out = String::new();
    match push_mathml(&mut out, parser, config) {
        Ok(()) => out
            .replace("<mo><</mo>", "<mo>&lt;</mo>")
            .replace("<mo>></mo>", "<mo>&gt;</mo>"),
        // Writing into a String cannot fail; keep the source visible anyway.
        Err(_) => format!("<code>{}</code>", escape(&latex)),
    }
}

/// `\sin^{2} x` → `{\sin}^{2}\, x`: pulldown-latex 0.8 puts the space it
/// adds before a function name inside the power when the name follows
/// another term (`A^2 \sin^2 q` came out as sin with a subscript-like 2).
fn powers_of_functions(latex: &str) -> String {
    const NAMES: [&str; 9] = [
        "\\sinh", "\\cosh", "\\tanh", "\\sin", "\\cos", "\\tan", "\\exp", "\\log", "\\ln",
    ];
    let mut out = String::with_capacity(latex.len() + 16);
    let mut rest = latex;
    'scan: while !rest.is_empty() {
        for name in NAMES {
            if let Some(after) = rest.strip_prefix(name).and_then(|r| r.strip_prefix('^')) {
                let power_len = match after.chars().next() {
                    Some('{') => balanced_group_len(after),
                    Some(c) => Some(c.len_utf8()),
                    None => None,
                };
                if let Some(n) = power_len {
                    out += &format!("{{{name}}}^{}\\,", &after[..n]);
                    rest = &after[n..];
                    continue 'scan;
                }
            }
        }
        let c = rest.chars().next().unwrap_or_default();
        out.push(c);
        rest = &rest[c.len_utf8()..];
    }
    out
}

/// The length of the `{…}` group at the start of `s`, braces balanced.
fn balanced_group_len(s: &str) -> Option<usize> {
    let mut depth = 0usize;
    for (i, c) in s.char_indices() {
        match c {
            '{' => depth += 1,
            '}' => {
                depth -= 1;
                if depth == 0 {
                    return Some(i + 1);
                }
            }
            _ => {}
        }
    }
    None
}

/// Text safe inside HTML: the characters markup reads, escaped.
pub fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}
