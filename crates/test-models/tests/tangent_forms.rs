//! The tangent recurrences of every model in test_models/ (forward mode or
//! Jacobian form, whichever its derivation chose) differentiate its
//! solution's recurrences: the solves of the numeric form, powers, square
//! roots, quotients and awkward names included.

#[path = "../../../tests/common/mod.rs"]
mod common;
use common::assert_tangent_recurrences_differentiate;

#[test]
fn every_test_model_s_tangent_recurrences_differentiate_its_solution_s() {
    macro_rules! check {
        ($($model:ident),*) => {$(
            assert_tangent_recurrences_differentiate(
                &mechlab_test_models::$model::Exact { params: Default::default() },
                stringify!($model),
            );
        )*};
    }
    check!(
        awkward_names,
        awkward_names_numeric,
        bare_pendulum,
        central_spring,
        double_pendulum_numeric,
        elliptic_pendulum,
        forced_oscillator,
        power_law_oscillator,
        quadruple_pendulum,
        rotating_hoop,
        spherical_pendulum,
        spring_chain5,
        spring_double_pendulum,
        van_der_pol
    );
}
