//! One module per `palc` subcommand.

pub mod zone;
