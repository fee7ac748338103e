//! Scene `painleve_stiff_limit`: the worked example as the rod stiffens,
//! ε = 0.1, 0.03, 0.01, 0.001.
//!
//! Both cases start from the same rod force R(0) as the worked example (the
//! deformation scaled as δ(0) ∝ ε², so that the reduced deformation equation
//! sees the same start): in the regular case R(t) settles to the rigid rod's
//! R* within a time O(ε); in the impact case the stop, the reversal and the
//! final stop happen ever more abruptly. The stiff rod needs the stiff
//! method: Radau IIA 5 between switches. Reported per run: the event times,
//! wall time and steps.

use mechlab::contact::StickSlip;
use mechlab::models::painleve_klein::{Contacts, Params};
use mechlab::ode::Method;
use mechlab::plot::{palette, Figure, PanelSpec, GREY};
use mechlab::scene::{knob, run, Scene};
use mechlab::studies::painleve::{phi_slope, reduced, rigid_rod_roots, rod};
use std::time::Instant;

fn main() {
    run(|| {
        let scene = Scene::from_args(
            "painleve_stiff_limit",
            "the worked example for ε → 0: R(t) → R*, sharpening friction impact, event times, cost",
            &[
                knob("eps_values", "0.1,0.03,0.01,0.001", "values of ε"),
                knob("x2_regular", "-0.65", "x2(0) of the regular case at ε = 0.1"),
                knob("x2_impact", "-0.78", "x2(0) of the impact case at ε = 0.1"),
                knob("t_end", "2", "end time"),
                knob("method", "radau5", "integration method between switches"),
                knob("tol", "1e-8", "tolerance"),
            ],
        )?;
        let eps_values = scene.numbers("eps_values")?;
        let t_end = scene.positive("t_end")?;
        let method = Method::parse(scene.text("method"), scene.positive("tol")?)?;
        let base = Params::default();
        let q = reduced(&base);
        let r_star = rigid_rod_roots(1.0, &q)
            .into_iter()
            .find(|r| phi_slope(*r, 1.0, &q) > 0.0);
        println!("rigid rod: stable root R* = {r_star:?}");
        let times: Vec<f64> = (0..=3000).map(|i| t_end * i as f64 / 3000.0).collect();
        // The start with the worked example's rod length at ε = 0.1, scaled by ε².
        let start = |x2_ref: f64, eps: f64| {
            let delta_ref = x2_ref.hypot(base.d) - base.l;
            let delta = delta_ref * (eps / 0.1).powi(2);
            let x2 = -((base.l + delta).powi(2) - base.d * base.d).sqrt();
            [0.0, x2, 10.0, 10.0]
        };
        let mut runs = Vec::new();
        let mut rows = Vec::new();
        for (label, x2_ref) in [
            ("regular", scene.number("x2_regular")?),
            ("impact", scene.number("x2_impact")?),
        ] {
            for &eps in &eps_values {
                let params = Params { eps, ..base };
                let y0 = start(x2_ref, eps);
                let clock = Instant::now();
                let result =
                    StickSlip::new(method).run(&Contacts { params }, 0.0, &y0, t_end, &times)?;
                let seconds = clock.elapsed().as_secs_f64();
                let steps: u64 = result.phases.iter().map(|p| p.stats.steps).sum();
                let f_evals: u64 = result.phases.iter().map(|p| p.stats.f_evals).sum();
                let events: Vec<(f64, String)> = result
                    .switches
                    .iter()
                    .map(|s| (s.t, format!("point {} {}", s.contact + 1, s.case)))
                    .collect();
                let final_r = rod(&result.y, &params).reaction;
                println!(
                    "{label:8} ε = {eps:<6} {:?} at t = {:.6}, R = {final_r:.6}, {steps} steps, {f_evals} f, {:.4} s, events {events:?}",
                    result.outcome, result.t, seconds
                );
                rows.push((
                    label,
                    eps,
                    format!("{:?}", result.outcome),
                    result.t,
                    final_r,
                    steps,
                    f_evals,
                    seconds,
                ));
                runs.push((label, eps, result, seconds, steps, final_r, params));
            }
        }

        // Fast time τ = t/ε: the transient and the impact take O(ε) time;
        // the impact force grows like 1/ε, so it is drawn as εR.
        let tau_regular = 30.0;
        let tau_impact = runs
            .iter()
            .filter(|r| r.0 == "impact")
            .fold(1.0f64, |m, r| m.max(r.2.t / r.1));
        let scaled_force = |label: &str| {
            runs.iter()
                .filter(|r| r.0 == label)
                .flat_map(|r| {
                    let factor = if label == "impact" { r.1 } else { 1.0 };
                    r.2.samples
                        .iter()
                        .map(move |(_, y)| factor * rod(y, &r.6).reaction)
                        .collect::<Vec<_>>()
                })
                .fold((f64::MAX, f64::MIN), |(l, h), v| (l.min(v), h.max(v)))
        };
        let (lo_r, hi_r) = scaled_force("regular");
        let (lo_i, hi_i) = scaled_force("impact");
        let all_times: Vec<f64> = runs
            .iter()
            .flat_map(|r| r.2.switches.iter().map(|s| s.t))
            .collect();
        let t_lo = all_times.iter().fold(f64::MAX, |m, t| m.min(*t)).max(1e-9);
        let t_hi = all_times
            .iter()
            .fold(0.0f64, |m, t| m.max(*t))
            .max(2.0 * t_lo);
        let eps_lo = eps_values.iter().fold(f64::MAX, |m, e| m.min(*e));
        let eps_hi = eps_values.iter().fold(0.0f64, |m, e| m.max(*e));
        let specs = [
            PanelSpec::new(
                "regular: R against t/ε",
                "t/ε",
                "R",
                (0.0, tau_regular),
                (lo_r.min(hi_r - 0.1), hi_r),
            ),
            PanelSpec::new(
                "impact: εR against t/ε",
                "t/ε",
                "εR",
                (0.0, tau_impact),
                (lo_i, hi_i * 1.05),
            ),
            PanelSpec::new(
                "impact: switch times against ε",
                "ε",
                "t",
                (eps_lo / 1.5, eps_hi * 1.5),
                (t_lo / 1.5, t_hi * 1.5),
            )
            .log_log(),
        ];
        let mut figure = Figure::grid(3, 1, 560, 440, &specs);
        let mut legend = Vec::new();
        for (label, eps, result, _, _, _, params) in &runs {
            let impact = *label == "impact";
            let k = usize::from(impact);
            let factor = if impact { *eps } else { 1.0 };
            let color = palette(eps_values.iter().position(|e| e == eps).unwrap_or(0));
            let curve: Vec<(f64, f64)> = result
                .samples
                .iter()
                .map(|(t, y)| (t / eps, factor * rod(y, params).reaction))
                .collect();
            figure.line(k, &curve, color);
            for s in &result.switches {
                figure.points(
                    k,
                    [(s.t / eps, factor * rod(&s.y, params).reaction)],
                    color,
                    7,
                );
                if impact {
                    figure.points(2, [(*eps, s.t)], color, 7);
                }
            }
            if !impact {
                legend.push((format!("ε = {eps}"), color));
            }
        }
        if let Some(r) = r_star {
            figure.line(0, &[(0.0, r), (tau_regular, r)], GREY);
            legend.push(("rigid rod R*".into(), GREY));
        }
        figure.legend(0, &legend);
        figure.legend(1, &legend[..eps_values.len()]);
        scene.save_figure(&figure, "stiff_limit.png")?;
        scene.write_csv(
            "runs.csv",
            &[
                "case", "eps", "outcome", "t_end", "final_R", "steps", "f_evals", "seconds",
            ],
            rows,
        )?;
        #[derive(serde::Serialize)]
        struct Event {
            t: f64,
            point: usize,
            case: String,
        }
        #[allow(non_snake_case)]
        #[derive(serde::Serialize)]
        struct Run {
            case: &'static str,
            eps: f64,
            outcome: String,
            t_end: f64,
            final_R: f64,
            steps: u64,
            seconds: f64,
            events: Vec<Event>,
        }
        #[allow(non_snake_case)]
        #[derive(serde::Serialize)]
        struct Summary {
            rigid_R_star: Option<f64>,
            runs: Vec<Run>,
        }
        let summary: Vec<Run> = runs
            .iter()
            .map(|(label, eps, result, seconds, steps, final_r, _)| Run {
                case: label,
                eps: *eps,
                outcome: format!("{:?}", result.outcome),
                t_end: result.t,
                final_R: *final_r,
                steps: *steps,
                seconds: *seconds,
                events: result
                    .switches
                    .iter()
                    .map(|s| Event {
                        t: s.t,
                        point: s.contact + 1,
                        case: s.case.clone(),
                    })
                    .collect(),
            })
            .collect();
        scene.write_summary(&Summary {
            rigid_R_star: r_star,
            runs: summary,
        })?;
        Ok(())
    });
}
