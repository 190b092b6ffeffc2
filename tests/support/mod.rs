//! Test support: a fake OpenAI-compatible server, the hand-written fixture replies, and
//! the verification helpers.
#![allow(dead_code)]
#![allow(clippy::unwrap_used)] // test helpers: a failure is a failed test

pub mod bench;
pub mod btcpp;
pub mod check;
pub mod cli;
pub mod embedded;
pub mod engine;
pub mod eval_goals;
pub mod fake_model;
pub mod fake_openai;
pub mod fixtures;
pub mod microphone;
pub mod multipart;
pub mod recorded;
pub mod repo;
pub mod rerun;
pub mod spread;
pub mod tmux;
pub mod verify;
pub mod workbench;
