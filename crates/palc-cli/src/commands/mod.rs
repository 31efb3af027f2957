//! One module per `palc` subcommand.

pub mod traffic;
pub mod zone;
