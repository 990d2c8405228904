//! Simulating one recording and tracking its cells' channels over it.

use super::plan::Case;
use super::{cell_channel_config, measure_cell, CellMeasured, FS_HZ, PRNS};
use crate::if_sim::{
    self, satellites_with_cn0, scenario_toml_with_oscillator, static_receiver, ChannelSpec,
    ChannelTrace, Oscillator, SimSource, Truth, SEOUL_LLH,
};

/// Simulates `case` with the receiver oscillator `osc` and measures its cells (aided by the
/// true carrier phase, which includes the receiver clock, or unaided).
pub(super) fn run_case(
    case: &Case,
    aided: bool,
    osc: &Oscillator,
) -> anyhow::Result<Vec<CellMeasured>> {
    let sats: Vec<(u8, f64)> = PRNS.iter().map(|&p| (p, case.cn0_dbhz)).collect();
    let text = scenario_toml_with_oscillator(
        case.duration_s,
        case.seed,
        FS_HZ,
        &static_receiver(SEOUL_LLH),
        &satellites_with_cn0(&sats),
        "",
        osc,
    );
    let sim = if_sim::simulator(&text)?;
    let truth = Truth::new(&sim);
    let mut specs = Vec::new();
    for (cell, _) in &case.cells {
        for &prn in &PRNS {
            specs.push(ChannelSpec {
                prn,
                config: cell_channel_config(cell.order, cell.bn_hz, cell.t_s()),
                doppler_offset_hz: 0.0,
            });
        }
    }
    let aid_fn = |prn: gpsrx_dsp::Prn, t: f64| truth.aid(prn.get(), t);
    let aid: Option<gpsrx_receiver::pipeline::channels::AidSource<'_>> =
        if aided { Some(&aid_fn) } else { None };
    let mut src = SimSource::new(&sim);
    let traces = if_sim::track_vs_truth(&mut src, &sim, &truth, &specs, aid)?;
    Ok(case
        .cells
        .iter()
        .enumerate()
        .map(|(i, (cell, settle))| {
            let tr: Vec<&ChannelTrace> = traces[i * PRNS.len()..(i + 1) * PRNS.len()]
                .iter()
                .collect();
            measure_cell(cell, &tr, *settle, !aided)
        })
        .collect())
}
