//! The models of `test_models/`, derived like the users' models.

fn main() {
    mechlab_derive::build_models("../..", "test_models");
}
