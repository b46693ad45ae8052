//! A quick look at some columns of a results CSV (`bg-sim plot --columns`).

use std::path::Path;

use bg_model::plots::{Panel, Plot, Series};

use super::{PlotError, Results};

/// A quick look at some columns of a results CSV (`bg-sim plot --columns`): one panel per
/// column over `t`, each labelled with the column's name, in a plot whose file is `stem`. A
/// column the results do not have is an error naming it and the similar ones.
pub fn quick_look(
    results: &Results,
    csv: &Path,
    stem: &str,
    columns: &[String],
) -> Result<Plot, PlotError> {
    if columns.is_empty() {
        return Err(PlotError::Column {
            path: csv.to_path_buf(),
            message: "--columns names no column".to_owned(),
            hint: bg_model::plots::column_hint("", results.names()),
        });
    }
    if let Some(c) = columns.iter().find(|c| results.column(c).is_none()) {
        return Err(PlotError::Column {
            path: csv.to_path_buf(),
            message: format!("no column `{}`", bg_model::error::clip(c)),
            hint: bg_model::plots::column_hint(c, results.names()),
        });
    }
    Ok(Plot {
        file: stem.to_owned(),
        title: format!(
            "{} of {}",
            columns.join(", "),
            csv.file_name().map_or_else(
                || csv.display().to_string(),
                |n| n.to_string_lossy().into_owned()
            )
        ),
        x: "t".to_owned(),
        x_label: "time [s]".to_owned(),
        panels: columns
            .iter()
            .map(|c| Panel {
                y_label: c.clone(),
                unit: None,
                x_range: None,
                series: vec![Series {
                    column: c.clone(),
                    label: c.clone(),
                    scale: 1.0,
                    offset: 0.0,
                    dashed: false,
                    line: 0,
                }],
                line: 0,
            })
            .collect(),
        line: 0,
    })
}
