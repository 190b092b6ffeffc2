//! The slow tier: the real language model and Whisper, the tmux suites, the pip anchors
//! (BehaviorTree.CPP's bindings, PyBullet and OMPL, the rerun viewer), the kill tests and
//! the arms' end-to-end runs. One test binary (each former test file is a module here);
//! `bash scripts/test.sh slow` runs it a module at a time, as the separate binaries ran
//! (docs/BUILD.md).

#[path = "../support/mod.rs"]
mod support;

mod bench_cmd;
mod btcpp_runs;
mod cell_arms;
mod dictation;
mod eval_cmds;
mod fetch_kill;
mod first_run;
mod local_model;
mod monitor_btcpp;
mod motion_anchor;
mod mujoco;
mod policy_kill;
mod recording;
mod run_anywhere;
mod tui_readings;
mod tui_tmux;
mod tui_tmux_big_tree;
mod tui_tmux_dead_ends;
mod viz_rrd;
mod viz_web;
