//! `--set "force of egg = 5 N"`: the library's setting parser (`session::repair::values`) at the
//! command line's edge.

use anyhow::{Context as _, Result};

use betr::scenario::Scenario;
pub use betr::session::repair::values::Setting;

pub fn parse_setting(scenario: &Scenario, text: &str) -> Result<Setting> {
    betr::session::repair::values::parse_setting(scenario, text).context("--set")
}
