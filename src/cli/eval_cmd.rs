//! `betr eval goals`: score goal interpretations against the LLM-OBTEA dataset.

use std::path::Path;
use std::process::ExitCode;

use anyhow::{Context, Result};

use betr::dataset;
use betr::domain::Scenario;
use betr::eval::{self, chart, goals};
use betr::store::write_atomic;

/// Score a file of recorded answers (one line per case) and write the results.
pub fn goals_from_answers(
    dataset_dir: &Path,
    answers: &Path,
    scenario: &Path,
    out: Option<&Path>,
) -> Result<ExitCode> {
    let cases = dataset::load(dataset_dir)?;
    let scenario = Scenario::load(scenario)?;
    let lines = goals::read_answers(answers, cases.len())?;
    let scored: Vec<goals::CaseResult> = cases
        .iter()
        .zip(&lines)
        .map(|(case, answer)| goals::score(&scenario.domain.vocabulary, case, answer.as_deref()))
        .collect();
    let results = goals::GoalsResults::from_cases(scored);
    let label = format!("answers from {}", answers.display());
    let dir = eval::output_dir(out, "goals").context("creating the output directory")?;
    write_results(&dir, &label, &results)?;
    print!("{}", results.table(&label));
    println!("\nresults: {}", dir.display());
    Ok(ExitCode::SUCCESS)
}

fn write_results(dir: &Path, label: &str, results: &goals::GoalsResults) -> Result<()> {
    let json = serde_json::to_string_pretty(results)?;
    write_atomic(&dir.join("results.json"), json.as_bytes()).context("writing results.json")?;
    write_atomic(&dir.join("results.csv"), results.csv().as_bytes())
        .context("writing results.csv")?;
    write_atomic(&dir.join("table.md"), results.table(label).as_bytes())
        .context("writing table.md")?;
    let png = dir.join("accuracy.png");
    match chart::accuracy_chart(
        &png,
        "Goal interpretation accuracy (LLM-OBTEA cafe set)",
        &eval::goals_series(label, results),
    ) {
        Ok(()) => {}
        // The numbers are written; a missing font only costs the picture.
        Err(e) => eprintln!("warning: chart not drawn: {e}"),
    }
    Ok(())
}
