use mechlab::analysis::lyapunov::lyapunov_spectrum;
use mechlab::models::kapitza;
use mechlab::ode::{Integrator, Method};
use rayon::prelude::*;
fn main() {
    let mut cases = vec![];
    for eps in [0.3, 0.5, 0.7, 1.0] { for a in [0.5, 1.0, 1.5, 2.0, 3.0] { for mu in [0.1, 0.2, 0.4] { cases.push((eps, a, mu)); } } }
    let out: Vec<String> = cases.par_iter().map(|&(eps, a, mu)| {
        let params = kapitza::Params { A: a, eps, mu };
        let sys = kapitza::Exact { params };
        let period = std::f64::consts::TAU * eps;
        let mut i = Integrator::new(Method::parse("dop853", 1e-9).unwrap()).unwrap();
        match lyapunov_spectrum::<_, 2, 6>(&mut i, &sys, period, &[1.0, 0.3], 500, 2000, &[true, false]) {
            Ok((l, y)) => format!("eps {eps} A {a} mu {mu}: {:.4} {:.4} sum {:.4} expected {:.4} end {y:?}", l[0], l[1], l[0]+l[1], -mu*period),
            Err(e) => format!("eps {eps} A {a} mu {mu}: {e}"),
        }
    }).collect();
    for o in out { println!("{o}"); }
}
