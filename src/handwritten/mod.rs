//! Right-hand sides written by hand, for systems whose model files do not
//! exist yet. Each one is replaced by a generated model when its study comes
//! (the model format then grows the feature it needs).

pub mod sliding_rod;
