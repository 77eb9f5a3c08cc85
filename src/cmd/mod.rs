//! One module per subcommand.
pub mod albedo;
pub mod eval;
pub mod info;
pub mod material;
