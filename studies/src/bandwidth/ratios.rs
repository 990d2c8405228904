//! Seed 004 Table 2: the Bn = 4 Hz over Bn = 1 Hz pseudorange-rate error ratios.

use super::CellResult;

/// Ratio of the Bn = 4 Hz to the Bn = 1 Hz pseudorange-rate error std at each (C/N0, order, T).
#[derive(Debug, Clone, serde::Serialize)]
pub struct TableTwoRatio {
    /// C/N0, dB-Hz.
    pub cn0_dbhz: f64,
    /// PLL order.
    pub order: u8,
    /// Integration time, ms.
    pub t_ms: u32,
    /// Measured ratio of the NCO Doppler error std.
    pub nco_measured: f64,
    /// Theory (digital loop).
    pub nco_theory: f64,
    /// Measured ratio over 0.1 s.
    pub obs_0p1s_measured: f64,
    /// Theory over 0.1 s.
    pub obs_0p1s_theory: f64,
    /// Measured ratio over 1 s.
    pub obs_1s_measured: f64,
    /// Theory over 1 s.
    pub obs_1s_theory: f64,
}

/// The Table-2 ratios of all (C/N0, order, T) that have both a locked 1 Hz and 4 Hz cell.
pub fn table_two_ratios(results: &[CellResult]) -> Vec<TableTwoRatio> {
    let mut out = Vec::new();
    for r1 in results.iter().filter(|r| r.cell.bn_hz == 1.0 && r.locked()) {
        let Some(r4) = results.iter().find(|r| {
            r.cell.bn_hz == 4.0
                && r.cell.cn0_dbhz == r1.cell.cn0_dbhz
                && r.cell.order == r1.cell.order
                && r.cell.t_ms == r1.cell.t_ms
                && r.locked()
        }) else {
            continue;
        };
        let (m1, m4, t1, t4) = (&r1.measured, &r4.measured, &r1.theory, &r4.theory);
        out.push(TableTwoRatio {
            cn0_dbhz: r1.cell.cn0_dbhz,
            order: r1.cell.order,
            t_ms: r1.cell.t_ms,
            nco_measured: m4.doppler_hz / m1.doppler_hz,
            nco_theory: t4.doppler_hz / t1.doppler_hz,
            obs_0p1s_measured: m4.pr_rate_mps / m1.pr_rate_mps,
            obs_0p1s_theory: t4.pr_rate_mps / t1.pr_rate_mps,
            obs_1s_measured: m4.pr_rate_1s_mps / m1.pr_rate_1s_mps,
            obs_1s_theory: t4.pr_rate_1s_mps / t1.pr_rate_1s_mps,
        });
    }
    out
}
