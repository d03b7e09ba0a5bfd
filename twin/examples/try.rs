//! Try a scene from the command line: `cargo run -p noback-twin --example try -- SCENE ...`.
fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    std::process::exit(noback_twin::cli::dispatch(&args));
}
