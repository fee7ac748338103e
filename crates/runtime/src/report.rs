//! The browsable report: one static `index.html` over the scenes' outputs,
//! a section per deliverable with its figure, the key numbers read from the
//! scene's `summary.json`, a line saying what it shows and the derivations
//! behind it as formulas (MathML, which browsers draw natively). No
//! network, no script: the figures are linked files.

use crate::mathml::escape;
use crate::registry::Catalog;
use serde_json::Value;
use std::path::Path;

/// One deliverable: where its figure and numbers come from.
pub struct Section {
    pub id: &'static str,
    pub title: &'static str,
    pub scene: &'static str,
    pub figure: &'static str,
    pub shows: &'static str,
    /// (label, JSON pointer into summary.json).
    pub numbers: &'static [(&'static str, &'static str)],
    /// The model whose derivations explain the figure, and their keys.
    pub formulas: (&'static str, &'static [&'static str]),
}

const KAPITZA: (&str, &[&str]) = ("kapitza", &["hamiltonian", "averaged_hamiltonian"]);
const KAPITZA_SECOND: (&str, &[&str]) = (
    "kapitza",
    &["vibrational_potential", "averaged_hamiltonian_second_order"],
);
const DOUBLE: (&str, &[&str]) = ("double_pendulum", &["hamiltonian", "averaged_hamiltonian"]);
const DOUBLE_STABILITY: (&str, &[&str]) = (
    "double_pendulum",
    &["vibrational_potential", "effective_potential"],
);
const PAINLEVE: (&str, &[&str]) = ("painleve_klein", &["free_force[0]", "normal_force[0]"]);
const NONE: (&str, &[&str]) = ("", &[]);

/// The derivations listed at the end of the report, per model.
pub const DERIVATION_KEYS: &[&str] = &[
    "hamiltonian",
    "averaged_hamiltonian",
    "vibrational_potential",
    "free_force[0]",
    "normal_force[0]",
];

/// Every deliverable, in study order.
pub const SECTIONS: &[Section] = &[
    Section { id: "1.2-1.4", title: "Kapitza pendulum: period map", scene: "kapitza_period_map", figure: "portrait_A1.png",
        shows: "Orbits of the period map on the cylinder; at A = 1 a chaotic sea around islands of regular motion (portrait_A0.png: the ordinary pendulum; portrait_A0.2.png: chaos only near the separatrices).",
        numbers: &[("ε", "/eps"), ("μ", "/mu")],
        formulas: KAPITZA },
    Section { id: "1.5-1.6", title: "Kapitza pendulum: the upper position", scene: "kapitza_stability", figure: "orbits_near_upper_position.png",
        shows: "Orbits near q = 0 below and above the critical amplitude A*, and the spiral into q = 0 with friction.",
        numbers: &[("A* (exact)", "/a_star"), ("A* (averaged, √2)", "/a_star_averaged"), ("A* (averaged to second order)", "/a_star_second_order"), ("verdict at the given A", "/verdict")],
        formulas: KAPITZA_SECOND },
    Section { id: "1.6", title: "Kapitza pendulum: stability chart", scene: "kapitza_stability", figure: "stability_chart.png",
        shows: "Where q = 0 is stable in the (ε, A) plane: above √2 for small ε (the dots: the second-order averaged threshold, √2 + 7√2/16 ε²), and bounded above by parametric resonance.",
        numbers: &[],
        formulas: KAPITZA_SECOND },
    Section { id: "1.4", title: "Kapitza pendulum: FLI chaos map", scene: "kapitza_chaos_map", figure: "chaos_map_viridis.png",
        shows: "Every point shaded by the fast Lyapunov indicator of its orbit: the chaotic layer along the separatrices.",
        numbers: &[("chaotic fraction", "/chaotic_fraction"), ("seconds", "/seconds")],
        formulas: KAPITZA },
    Section { id: "1-web", title: "Illustration: the standard map", scene: "standard_map", figure: "chaos_map.png",
        shows: "The stochastic web of the Chirikov standard map at ε = 0.16.",
        numbers: &[("ε", "/eps"), ("chaotic fraction", "/chaotic_fraction")],
        formulas: NONE },
    Section { id: "1.7", title: "Kapitza pendulum: strange attractor", scene: "kapitza_attractor", figure: "attractor.png",
        shows: "With friction the period map settles on a Hénon-like strange attractor.",
        numbers: &[("Lyapunov exponents", "/lyapunov"), ("box-counting dimension", "/dimension"), ("Kaplan–Yorke dimension", "/kaplan_yorke_dimension")],
        formulas: KAPITZA },
    Section { id: "2.2", title: "Double pendulum: Theorem 2", scene: "double_pendulum_averaging", figure: "averaging.png",
        shows: "Exact (large ν) and limiting systems from the same (q, p): coordinates coincide to O(1/ν), velocities differ by O(1).",
        numbers: &[("ν", "/nu"), ("max deviation, first case", "/cases/0/max_deviation")],
        formulas: DOUBLE },
    Section { id: "2.3", title: "Double pendulum: deviation of order 1/ν", scene: "double_pendulum_convergence", figure: "convergence.png",
        shows: "Max deviation against ν on log-log axes (slope −1) and ν × max deviation levelling off.",
        numbers: &[("slopes", "/slope"), ("observation time", "/t_obs")],
        formulas: DOUBLE },
    Section { id: "2.4", title: "Double pendulum: stabilisation", scene: "double_pendulum_stabilization", figure: "stabilization.png",
        shows: "Limiting runs above and below a*, and the exact system's spectral radius against a: stable from a* up to a parametric resonance.",
        numbers: &[("a* at (0, 0)", "/equilibria/0/a_star"), ("a* to second order in 1/ν at (0, 0)", "/equilibria/0/a_star_second_order"), ("a* at (0, π)", "/equilibria/1/a_star"), ("exact window at (0, 0)", "/equilibria/0/exact_window"), ("formula at (0, 0)", "/equilibria/0/a_star_formula")],
        formulas: DOUBLE_STABILITY },
    Section { id: "2.5", title: "Double pendulum: Theorem 3 with friction", scene: "double_pendulum_friction", figure: "friction.png",
        shows: "A perturbation decays in both systems; the exact Floquet multipliers lie inside the unit circle as the averaged eigenvalues predict.",
        numbers: &[("max Re λ (averaged)", "/max_real_part"), ("μ", "/mu"), ("a", "/a")],
        formulas: DOUBLE },
    Section { id: "3.1-3.2", title: "Painlevé–Klein: the graphs of Φ", scene: "painleve_phi", figure: "phi.png",
        shows: "The six qualitatively different graphs of Φ(R), their regions, and the roots for the worked example.",
        numbers: &[("roots, σ = +1", "/given/0/roots"), ("case, σ = +1", "/given/0/case")],
        formulas: PAINLEVE },
    Section { id: "3.3-3.4", title: "Painlevé–Klein: the deformation equation", scene: "painleve_delta", figure: "portraits.png",
        shows: "Equilibria of (25) with their stability, and phase portraits for ν = 0 and ν ≠ 0 for every class.",
        numbers: &[("worked example equilibria", "/cases/6/equilibria")],
        formulas: PAINLEVE },
    Section { id: "3.5-3.6", title: "Painlevé–Klein: friction impact", scene: "painleve_klein_impact", figure: "impact.png",
        shows: "The worked example with stick–slip switching: constant acceleration from x2(0) = −0.65, a friction impact and rest from −0.78.",
        numbers: &[("events of the impact", "/cases/1/events"), ("final states", "/cases/1/final")],
        formulas: PAINLEVE },
    Section { id: "3.x", title: "Painlevé–Klein: the stiff limit", scene: "painleve_stiff_limit", figure: "stiff_limit.png",
        shows: "ε = 0.1 … 0.001: R(t) → R* in fast time, the impact sharpening, switch times against ε.",
        numbers: &[("rigid R*", "/rigid_R_star")],
        formulas: PAINLEVE },
    Section { id: "cost", title: "Work against precision", scene: "work_precision", figure: "kapitza_chaotic.png",
        shows: "Error against time and f-evaluations for every method on the chaotic Kapitza orbit (other problems beside it).",
        numbers: &[("slopes (chaotic Kapitza)", "/slopes_error_vs_f_evals/kapitza_chaotic"), ("periods per second at 1e-10", "/performance/periods_per_second_at_1e-10")],
        formulas: NONE },
];

/// The formulas of `keys` of the model `name`, each with what it is.
fn formulas(catalog: Catalog, name: &str, keys: &[&str]) -> String {
    let Ok(model) = crate::registry::lookup(catalog, name).map(|m| m.info) else {
        return String::new();
    };
    let mut html = String::new();
    for key in keys {
        if let Some(d) = model.derivations.iter().find(|d| d.key == *key) {
            html += &format!(
                "<div class=\"formula\"><small>{} — {}</small>{}</div>\n",
                escape(model.name),
                escape(d.description),
                crate::mathml::mathml(d.latex, true)
            );
        }
    }
    html
}

/// The report (on the models of `catalog`) over the scene outputs under `out` (one folder per scene):
/// each section's figure beside its derivations, its numbers, and at the
/// end the main derivations of every model. Sections whose outputs are
/// missing say so and link nothing.
pub fn index_html(catalog: Catalog, out: &Path) -> String {
    let mut html = String::from(
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>mechlab report</title>\n<style>body{font-family:sans-serif;max-width:1200px;margin:auto;padding:1em}img{max-width:100%;border:1px solid #ddd}.row{display:flex;gap:1em;align-items:flex-start}.row>a{flex:3}.row>.formulas{flex:2}.formula{border-left:3px solid #dde;padding:0 0.5em;margin:0.4em 0}.formula small{color:#555}math{font-size:1.1em}table{border-collapse:collapse}td{border:1px solid #ddd;padding:2px 6px;vertical-align:top}</style></head><body>\n<h1>mechlab: the studies</h1>\n<p>Every section is one deliverable: its figure beside the derivations behind it, the key numbers from the scene's <code>summary.json</code>, and what it shows. Regenerate with <code>cargo run --release --example report</code>; explore interactively with <code>cargo run --release --example studio</code>.</p>\n",
    );
    html += "<ul>\n";
    for s in SECTIONS {
        html += &format!(
            "<li><a href=\"#{}\">{} {}</a></li>\n",
            s.id,
            s.id,
            escape(s.title)
        );
    }
    html += "<li><a href=\"#derivations\">Derivations</a></li>\n</ul>\n";
    for s in SECTIONS {
        html += &section(catalog, out, s);
    }
    html += "<h2 id=\"derivations\">Derivations</h2>\n<p>The main derived expressions of every model, in their readable forms (each checked against the computer algebra's result at build time).</p>\n";
    for model in catalog {
        html += &formulas(catalog, model.info.name, DERIVATION_KEYS);
    }
    html += "</body></html>\n";
    html
}

fn section(catalog: Catalog, out: &Path, s: &Section) -> String {
    let mut html = format!("<h2 id=\"{}\">{} {}</h2>\n", s.id, s.id, escape(s.title));
    let figure = out.join(s.scene).join(s.figure);
    let summary_path = out.join(s.scene).join("summary.json");
    let summary: Option<Value> = std::fs::read_to_string(&summary_path)
        .ok()
        .and_then(|t| serde_json::from_str(&t).ok());
    let Some(summary) = summary.filter(|_| figure.exists()) else {
        return html
            + &format!(
                "<p><em>Not run yet: <code>cargo run --release --example {}</code>.</em></p>\n",
                s.scene
            );
    };
    html += &format!(
        "<p>{}</p>\n<div class=\"row\"><a href=\"{scene}/{fig}\"><img src=\"{scene}/{fig}\" alt=\"{}\"></a><div class=\"formulas\">{}</div></div>\n",
        escape(s.shows),
        escape(s.title),
        formulas(catalog, s.formulas.0, s.formulas.1),
        scene = s.scene,
        fig = s.figure
    );
    html += "<table>\n";
    for (label, pointer) in s.numbers {
        let value = summary
            .pointer(pointer)
            .map(|v| v.to_string())
            .unwrap_or_else(|| "–".into());
        html += &format!(
            "<tr><td>{}</td><td><code>{}</code></td></tr>\n",
            escape(label),
            escape(&value)
        );
    }
    html + &format!(
        "</table>\n<p>Data: <a href=\"{0}/summary.json\">{0}/summary.json</a></p>\n",
        s.scene
    )
}

/// Every `href` and `src` of a page, for checking that they exist.
pub fn links(html: &str) -> Vec<String> {
    let mut out = Vec::new();
    for attribute in ["href=\"", "src=\""] {
        let mut rest = html;
        while let Some(i) = rest.find(attribute) {
            rest = &rest[i + attribute.len()..];
            if let Some(j) = rest.find('"') {
                out.push(rest[..j].to_string());
                rest = &rest[j..];
            }
        }
    }
    out
}

/// The cargo arguments that run the scene `name` in release mode, up to
/// its output folder (which follows): a scene is an example, the
/// work–precision benchmark runs through `cargo bench`, whose profile is
/// already the optimised one (cargo refuses `bench --release`).
pub fn scene_command(name: &str) -> Vec<&str> {
    if name == "work_precision" {
        vec!["bench", "--quiet", "--bench", name, "--", "--out"]
    } else {
        vec![
            "run",
            "--release",
            "--quiet",
            "--example",
            name,
            "--",
            "--out",
        ]
    }
}

/// A model's derivations as a document (the `model_report` scene): its
/// file, each derived expression in LaTeX, the cost of its generated
/// right-hand sides, and the generated code itself.
#[derive(serde::Serialize)]
pub struct ModelReport {
    pub model: &'static str,
    pub expressions: usize,
    pub generated_lines: usize,
    /// (function, derived, readable, emitted)
    pub operation_counts: &'static [(&'static str, usize, usize, usize)],
    #[serde(skip)]
    info: &'static crate::registry::ModelInfo,
}

/// The report of `info`.
pub fn model_report(info: &'static crate::registry::ModelInfo) -> ModelReport {
    ModelReport {
        model: info.name,
        expressions: info.derivations.len(),
        generated_lines: info.generated_code.lines().count(),
        operation_counts: info.operation_counts,
        info,
    }
}

/// One-step averaging of the Kapitza pendulum, said beside its derivations.
const KAPITZA_NOTE: &str = "One-step averaging (docs/studies.md, Study 1): the generating function \
    W = P q + ε f(q, P, θ) with f = A P sin q cos θ + (A²/8) sin²q sin 2θ removes the phase at order zero, \
    leaving Ĥ = H̄ + O(ε) with H̄ the averaged Hamiltonian above: P²/2 + cos Q + (A²/4) sin²Q. \
    Its upper position Q = 0 is stable when V''(0) = −1 + A²/2 > 0, i.e. A > √2.";

impl ModelReport {
    /// The document in Markdown with its LaTeX.
    pub fn markdown(&self) -> String {
        let model = self.info;
        let mut markdown = format!(
            "# Model `{}`\n\nFrom `{}`:\n\n```toml\n{}```\n\n",
            model.name, model.source_file, model.source
        );
        markdown += &format!(
            "Coordinates {:?}, momenta {:?}; parameters {:?}.\n\n",
            model.coordinates, model.momenta, model.parameter_names
        );
        for d in model.derivations {
            markdown += &format!(
                "## `{}`\n\n{}\n\n$$\n{}\n$$\n\n",
                d.key, d.description, d.latex
            );
        }
        if model.name == "kapitza" {
            markdown += &format!("## One-step averaging\n\n{KAPITZA_NOTE}\n");
        }
        markdown += "## Cost of the generated right-hand sides\n\n\
            Operations after common-subexpression elimination (transcendental calls count 20, \
            divisions 4): as derived, in the readable form above, and emitted.\n\n\
            | function | derived | readable | emitted |\n|---|---|---|---|\n";
        for (function, derived, readable, emitted) in model.operation_counts {
            markdown += &format!("| `{function}` | {derived} | {readable} | {emitted} |\n");
        }
        markdown
    }
}

impl crate::outputs::Outputs for ModelReport {
    fn figures(&self) -> Vec<(String, crate::plot::Figure)> {
        Vec::new()
    }
    fn texts(&self) -> Vec<(String, String)> {
        vec![
            ("derivations.md".into(), self.markdown()),
            ("generated.rs".into(), self.info.generated_code.into()),
        ]
    }
    fn lines(&self) -> Vec<String> {
        let model = self.info;
        let mut lines = vec![format!("model {} ({})\n", model.name, model.source_file)];
        for d in model.derivations {
            lines.push(format!("{}  [{}]\n    {}\n", d.key, d.description, d.text));
        }
        if model.name == "kapitza" {
            lines.push(format!("{KAPITZA_NOTE}\n"));
        }
        for (function, derived, readable, emitted) in model.operation_counts {
            lines.push(format!(
                "cost of {function}: derived {derived}, readable {readable}, emitted {emitted}"
            ));
        }
        lines
    }
}
