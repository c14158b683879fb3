//! The `polyscene` command-line tool: batch detection, simulation, replay
//! and evaluation. Run `polyscene help` for usage.

use polyscene::cli;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match cli::run(&args) {
        Ok(out) => {
            use std::io::Write;
            if !out.is_empty() {
                // A closed pipe (`| head`) is not an error worth a panic.
                let _ = writeln!(std::io::stdout(), "{out}");
            }
        }
        Err(e) => {
            eprintln!("polyscene: {e}");
            std::process::exit(2);
        }
    }
}
