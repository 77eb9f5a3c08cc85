//! One module per subcommand.
pub(crate) mod albedo;
pub(crate) mod check;
pub(crate) mod eval;
pub(crate) mod export;
pub(crate) mod fit;
pub(crate) mod info;
pub(crate) mod material;
pub(crate) mod output;
pub(crate) mod plot;
pub(crate) mod render;
pub(crate) mod shared;
pub(crate) mod synth;
