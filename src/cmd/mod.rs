//! One module per subcommand.
pub mod albedo;
pub mod check;
pub mod eval;
pub mod export;
pub mod fit;
pub mod info;
pub mod material;
pub mod output;
pub mod plot;
pub mod render;
pub mod shared;
pub mod synth;
