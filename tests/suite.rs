//! mechlab's tests, one module per file of `tests/`, in one binary (the
//! studio's and the derivations' snapshots have their own): one binary
//! compiles the integrators' and analyses' instances once and links the
//! models once. `cargo test --release NAME` runs the tests whose path
//! contains NAME, e.g. `cargo test --release section::`.

mod common;

mod analyses_by_name;
mod attractor;
mod bad_input;
mod basins;
mod bicycle;
mod bodies;
mod bricard;
mod constrained;
mod continuation;
mod declarations;
mod dimension;
mod docs_commands;
mod double_double;
mod events;
mod explore;
mod flyball_governor;
mod frequency;
mod holonomic;
mod indicators;
mod integrators;
mod massless;
mod mechanism;
mod model_errors;
mod morse_pendulum;
mod rattleback;
mod report;
mod runtime;
mod scene_output;
mod second_order;
mod section;
mod separatrix;
mod simplify_forms;
mod source_layout;
mod studies;
mod study2;
mod study3;
mod taylor;
mod taylor_lanes;
mod tippe_top;
mod trade;
mod turning_arm_spring;
mod verify_derivations;
