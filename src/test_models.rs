//! Models for tests and benchmarks only, generated from `test_models/` like
//! the users' models (not in [`crate::models::MODELS`], not offered by
//! the scenes): e.g. the double pendulum in the numeric-solve form, to be
//! compared with its symbolic-inverse form.

include!(concat!(env!("OUT_DIR"), "/generated/test_models.rs"));
