//! Helpers shared by the integration tests.
#![allow(dead_code)]

use mechlab::registry::Model;

/// The users' model `name`, which the test expects to exist.
pub fn model_of(name: &str) -> &'static Model {
    mechlab::models::by_name(name).unwrap_or_else(|e| panic!("{e}"))
}
