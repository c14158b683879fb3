//! The `polyscene` command-line tool: batch detection, simulation, replay
//! and evaluation. Run `polyscene --help` for usage. The logic is
//! `polyscene::internals::cli` (native builds only; on wasm32 this is an empty program).

#[cfg(not(target_arch = "wasm32"))]
fn main() {
    use std::io::Write;
    let args: Vec<String> = std::env::args().skip(1).collect();
    match polyscene::internals::cli::run(&args) {
        Ok(out) => {
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

#[cfg(target_arch = "wasm32")]
fn main() {}
