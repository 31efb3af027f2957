//! One module per `palc` subcommand.
