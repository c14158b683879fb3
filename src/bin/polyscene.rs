//! The `polyscene` command-line tool: batch detection, simulation, replay
//! and evaluation. Run `polyscene help` for usage.

use polyscene::cli;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match cli::run(&args) {
        Ok(out) => {
            if !out.is_empty() {
                println!("{out}");
            }
        }
        Err(e) => {
            eprintln!("polyscene: {e}");
            std::process::exit(2);
        }
    }
}
