//! Test support: a fake OpenAI-compatible server and the hand-written fixture replies.
#![allow(dead_code)]

pub mod cli;
pub mod fake_openai;
pub mod fixtures;
pub mod multipart;
