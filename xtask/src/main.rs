//! Project tasks for palc, run as `cargo xtask <task>` from anywhere in the
//! workspace (the alias lives in `.cargo/config.toml`).

fn main() -> anyhow::Result<()> {
    let task = std::env::args().nth(1);
    match task.as_deref() {
        None | Some("help" | "--help" | "-h") => {
            print_help();
            Ok(())
        }
        Some(other) => {
            print_help();
            anyhow::bail!("unknown task `{other}`")
        }
    }
}

fn print_help() {
    println!("cargo xtask <task>\n\ntasks:\n  help    this text");
}
