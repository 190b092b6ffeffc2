//! The fast tier: every integration test that needs no language or speech model, no
//! tmux, no Python virtual environment and no killed or timed child process — the fake
//! and scripted models, the fixtures, the snapshots, the fuzz seeds, the binary's short
//! commands. One test binary (each former test file is a module here); run it with
//! `bash scripts/test.sh fast` after every change (docs/BUILD.md).

#[path = "../support/mod.rs"]
mod support;

mod api_key;
mod bench_cmd;
mod bounds;
mod bt_api;
mod cafe_goals;
mod cafe_scenarios;
mod cell_scenarios;
mod closed_pipe;
mod command_line;
mod engine;
mod engine_dead_ends;
mod engine_debugger;
mod engine_verification;
mod eval_cmds;
mod eval_sessions;
mod example_pools;
mod executor;
mod full_disk;
mod fuzz;
mod goal_checks;
mod goal_dataset;
mod interop;
mod knowledge;
mod knowledge_shared;
mod llm_client;
mod llm_faults;
mod module_graph;
mod monitor_errors;
mod names;
mod recording;
mod resolve_loop;
mod run_anywhere;
mod scenario_doc;
mod scenario_files;
mod stt_client;
mod tui_model_arrival;
mod tui_panes;
mod tui_readings;
mod tui_snapshots;
mod verify_before_execution;
mod verify_cell;
mod verify_scenarios;
mod whole_lines;
