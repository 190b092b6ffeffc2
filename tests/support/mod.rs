//! Test support: a fake OpenAI-compatible server, the hand-written fixture replies, and
//! the verification helpers.
#![allow(dead_code)]

pub mod cli;
pub mod embedded;
pub mod fake_model;
pub mod fake_openai;
pub mod fixtures;
pub mod microphone;
pub mod multipart;
pub mod verify;
