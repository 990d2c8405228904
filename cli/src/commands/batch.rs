//! `gpsrx batch MANIFEST --out DIR`: the recordings of a manifest processed one after another
//! (a thin layer over [`gpsrx_receiver::batch`]), and its study grids case by case
//! ([`gpsrx_studies::grid`]).
//!
//! A recording that cannot be read or processed is a row with status `error` and its message
//! in `summary.csv`; the batch goes on. The exit status is 1 only when the manifest cannot be
//! used or every entry failed ([`crate::cli::BATCH_EXIT_STATUS`]).

use crate::cli::BatchArgs;
use crate::exit::Completion;
use anyhow::Context;
use gpsrx_receiver::batch::summary::{print_summary, write_summary_csv};
use gpsrx_receiver::batch::{run_batch, Manifest, Status, StudySpec};
use std::io::Write;
use std::path::Path;

/// Runs `gpsrx batch`.
pub fn run(args: &BatchArgs) -> anyhow::Result<Completion> {
    let manifest = Manifest::read(&args.manifest)?;
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("cannot create the output directory {}", args.out.display()))?;
    let total = manifest.recordings.len();
    let mut done = 0;
    let rows = run_batch(&manifest, &args.out, &mut |row| {
        done += 1;
        eprintln!("[{done}/{total}] {}: {}", row.name, row.status.name());
    });
    let summary = args.out.join("summary.csv");
    write_summary_csv(&summary, &rows)
        .with_context(|| format!("cannot write {}", summary.display()))?;
    let mut out = crate::exit::stdout();
    if !rows.is_empty() {
        print_summary(&mut out, &rows)?;
        writeln!(out, "summary: {}", summary.display())?;
    }
    let mut cases_ok = 0;
    for study in &manifest.studies {
        cases_ok += run_study(study, &args.out, &mut out)?;
    }
    out.flush()?;
    let any_fix = rows.iter().any(|r| r.status == Status::Ok);
    if any_fix || cases_ok > 0 {
        Ok(Completion::Done)
    } else {
        anyhow::bail!("every entry of the batch failed (see the summary above)")
    }
}

/// Runs the cases of one study grid in turn into `study-NAME.csv`; returns how many ran.
fn run_study(study: &StudySpec, out_dir: &Path, out: &mut dyn Write) -> anyhow::Result<usize> {
    let all = gpsrx_studies::grid::cases(&study.name, study.quick)?;
    let [start, end] = study.cases.unwrap_or([0, all.len()]);
    let end = end.min(all.len());
    let mut rows = Vec::new();
    let mut errors = Vec::new();
    for index in start..end {
        match gpsrx_studies::grid::run_case(&study.name, study.quick, index) {
            Ok(row) => rows.push(row),
            Err(e) => errors.push(format!("case {index}: {e:#}")),
        }
    }
    let path = out_dir.join(format!("study-{}.csv", study.name));
    write_rows_csv(&path, &rows).with_context(|| format!("cannot write {}", path.display()))?;
    writeln!(
        out,
        "study {}: {} of {} cases ran ({})",
        study.name,
        rows.len(),
        end.saturating_sub(start),
        path.display()
    )?;
    for e in &errors {
        writeln!(out, "  {e}")?;
    }
    Ok(rows.len())
}

/// Rows of name/value maps as CSV, the columns of the first row.
fn write_rows_csv(
    path: &Path,
    rows: &[serde_json::Map<String, serde_json::Value>],
) -> anyhow::Result<()> {
    let mut w = csv::Writer::from_path(path)?;
    let Some(first) = rows.first() else {
        w.flush()?;
        return Ok(());
    };
    let columns: Vec<&String> = first.keys().collect();
    w.write_record(&columns)?;
    for row in rows {
        w.write_record(columns.iter().map(|c| match row.get(*c) {
            Some(serde_json::Value::String(s)) => s.clone(),
            Some(v) => v.to_string(),
            None => String::new(),
        }))?;
    }
    w.flush()?;
    Ok(())
}
