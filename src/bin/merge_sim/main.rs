//! `merge_sim`: run, compare and inspect cooperative merge simulations with the built-in
//! planners. The command line lives in the library ([`mergesim::cli`]); a binary of one's own
//! with one's own planners calls `mergesim::cli::main_with(registry)` instead
//! (examples/own_planner_cli.rs).

fn main() -> std::process::ExitCode {
    mergesim::cli::main()
}
