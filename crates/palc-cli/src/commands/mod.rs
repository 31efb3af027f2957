//! One module per `palc` subcommand.

pub mod drive;
pub mod eval;
pub mod export;
pub mod import;
pub mod learn;
pub mod plan;
pub mod traffic;
pub mod user;
pub mod zone;
