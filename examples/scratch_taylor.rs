use mechlab::analysis::period_map::orbit;
use mechlab::models::kapitza;
use mechlab::ode::{Integrator, Method};
use std::time::Instant;
fn main() {
    let sys = kapitza::Exact { params: kapitza::Params { A: 1.5, eps: 0.1, mu: 0.0 } };
    let period = std::f64::consts::TAU * 0.1;
    let y0 = [std::f64::consts::PI - 0.5, 0.0];
    let periods = 1000;
    let mut r = Integrator::new(Method::Dop853 { rtol: 1e-15, atol: 1e-15 }).unwrap();
    let reference = orbit(&mut r, &sys, period, &y0, periods, &[false, false]).unwrap();
    let yr = reference[periods];
    for (name, tol) in [("dop853", 1e-9), ("dop853", 1e-11), ("dop853", 1e-13), ("taylor", 1e-6), ("taylor", 1e-8),("taylor", 1e-10), ("taylor", 1e-12), ("taylor", 1e-14), ("taylor", 1e-16)] {
        let mut it = Integrator::new(Method::parse(name, tol).unwrap()).unwrap();
        let start = Instant::now();
        let mut o = Vec::new();
        let reps = 5;
        for _ in 0..reps { it.stats = Default::default(); o = orbit(&mut it, &sys, period, &y0, periods, &[false, false]).unwrap(); }
        let el = start.elapsed().as_secs_f64() / reps as f64;
        let y = o[periods];
        let err = (y[0]-yr[0]).abs().max((y[1]-yr[1]).abs());
        println!("{name} {tol:e}: err {err:.2e}, {:.0} periods/s, steps/period {:.2}, order {}", periods as f64 / el, it.stats.steps as f64 / periods as f64, it.stats.order);
    }
}
