//! `gpsrx config --default`: print the default configuration file, commented.

use crate::cli::ConfigArgs;
use gpsrx_tracking::ChannelConfig;
use std::io::Write;

/// Runs `gpsrx config`.
pub fn run(args: &ConfigArgs) -> anyhow::Result<()> {
    if !args.default {
        anyhow::bail!("say what to print: `gpsrx config --default` prints the default gpsrx.toml");
    }
    let text = default_toml()?;
    let mut out = crate::exit::stdout();
    out.write_all(text.as_bytes())?;
    out.flush()?;
    Ok(())
}

/// The default configuration as commented TOML (valid input to `--config`).
pub fn default_toml() -> anyhow::Result<String> {
    let c = ChannelConfig::default();
    let w = c.weak_pull_in.unwrap_or_default();
    let loops = |name: &str, l: &gpsrx_tracking::LoopConfig| -> anyhow::Result<String> {
        Ok(format!(
            "[tracking.{name}]\n\
             pll_order = {}            # PLL order 1, 2 or 3 (0: FLL only)\n\
             pll_bw_hz = {:?}          # PLL noise bandwidth, Hz\n\
             fll_order = {}            # FLL assist order 0 (none), 1 or 2\n\
             fll_bw_hz = {:?}          # FLL noise bandwidth, Hz\n\
             dll_order = {}            # DLL order 1 or 2 (carrier-aided)\n\
             dll_bw_hz = {:?}          # DLL noise bandwidth, Hz\n\
             t_coh_s = {:?}            # integration time, s: 0.001 .. 0.020, a divisor of 20 ms\n\
             el_spacing_chips = {:?}   # early-late spacing, 0.1 .. 1 chip\n\
             pll_discriminator = \"{}\"  # costas (data) or atan2 (pilot)\n\
             fll_discriminator = \"{}\"  # data_insensitive or atan2\n\
             dll_discriminator = \"{}\"  # normalized_envelope or dot_product\n",
            l.pll_order,
            l.pll_bw_hz,
            l.fll_order,
            l.fll_bw_hz,
            l.dll_order,
            l.dll_bw_hz,
            l.t_coh_s,
            l.el_spacing_chips,
            enum_name(&l.pll_discriminator)?,
            enum_name(&l.fll_discriminator)?,
            enum_name(&l.dll_discriminator)?,
        ))
    };
    let text = format!(
        "# gpsrx configuration (gpsrx run/track --config gpsrx.toml).\n\
         # Every value here can be overridden on the command line (--pll-order, --pll-bw, ...).\n\
         # Unknown keys are errors.\n\
         \n\
         [tracking]\n\
         mode = \"scalar\"           # scalar, or vector: the navigation filter ([vector]) drives the channels after the first fix (--tracking)\n\
         min_pull_in_s = {:?}      # minimum pull-in time before the hand-over to [tracking.track], s\n\
         fll_assist_s = {:?}       # the pull-in FLL assist is switched off after this, s\n\
         cn0_lost_dbhz = {:?}      # C/N0 below which a channel counts as lost, dB-Hz\n\
         vector_cn0_lost_dbhz = {:?}  # the same for a channel the vector filter checks (its innovation test), dB-Hz\n\
         cn0_window_s = {:?}       # length of one C/N0 estimate (bit-aligned NWPR), s\n\
         lost_estimates = {}       # consecutive low estimates that release the channel\n\
         relock_after_s = {:?}     # out of phase lock this long in tracking: pull the carrier in again (state recover), s (0: never)\n\
         recover_s = {:?}          # a recovery not locked after this releases the channel (searched again), s\n\
         weak_enter_dbhz = {:?}    # below this C/N0 a channel takes [tracking.weak_track], dB-Hz (0: never)\n\
         weak_leave_dbhz = {:?}    # above this it goes back to [tracking.track], dB-Hz\n\
         correlator = \"{}\"       # widest correlator instruction set: auto, avx512, avx2 or scalar (--correlator)\n\
         correlator_arithmetic = \"{}\"  # auto (int16 on ci8 with AVX2, else f32), f32 or i16 (--correlator avx2/i16)\n\
         \n\
         # Pull-in loops: 1 ms, wide, FLL-assisted.\n{}\n\
         # Tracking loops after phase lock and bit synchronisation (--pll-order etc. set these).\n\
         # 3rd order at 18 Hz follows 10 g manoeuvres.\n{}\n\
         # Tracking loops for weak signals (C/N0 below weak_enter_dbhz): 20 ms, narrow.\n{}\n\
         # Tracking loops for weak signals the vector filter checks and feeds forward: narrower.\n{}\n\
         # Weak-signal pull-in (acquisition C/N0 below enter_dbhz): an FLL alone on 10 ms sums\n\
         # while the bits are synchronised differentially, then a bit-aligned 20 ms PLL, then\n\
         # [tracking.weak_track]. Remove the section's keys to keep its defaults.\n\
         [tracking.weak_pull_in]\n\
         enter_dbhz = {:?}         # acquisition C/N0 below which a channel takes this pull-in, dB-Hz (0: never)\n\
         fll_assist_s = {:?}        # the phase stage's FLL assist is switched off after this, s\n\
         bit_sync_dbhz = {:?}      # design C/N0 of the bit synchroniser's threshold, dB-Hz\n\
         p_false_sync = {:?}    # false bit-synchronisation probability it is sized for\n\
         lost_dbhz = {:?}          # C/N0 before bit sync below which the pull-in fails, dB-Hz\n\
         patience_s = {:?}         # longest weak pull-in, s\n\
         \n\
         # Frequency stage: FLL alone (pll_order = 0), 10 ms sums not aligned to the bits.\n{}\n\
         # Phase stage: bit-aligned 20 ms, FLL-assisted 3rd-order PLL.\n{}\n\
         # Tracking loops while an INS feed-forward aids the channel (gpsrx run --ins; optional,\n\
         # default: the same as [tracking.track]; --aided-pll-bw, --aided-pll-order):\n\
         # [tracking.aided_track]\n\
         # pll_order = 2\n\
         # pll_bw_hz = 3.0\n\
         # ... (give every key of [tracking.track]: missing ones take the pull-in defaults)\n\
         \n\
         [run]                     # gpsrx run (command-line options override these)\n\
         rate_hz = 10.0            # observable and fix rate, 1 .. 50 Hz (--rate)\n\
         elevation_mask_deg = 5.0  # elevation mask, deg (--elevation-mask)\n\
         iono = \"klobuchar\"        # klobuchar or none (--iono)\n\
         tropo = \"saastamoinen\"    # saastamoinen or none (--tropo)\n\
         raim_pfa = 0.001          # RAIM false-alarm probability (--raim-pfa)\n\
         doppler_max_hz = 5000.0   # acquisition Doppler half-width, Hz (--doppler-max)\n\
         doppler_center_hz = 0.0   # acquisition Doppler centre: front-end LO offset, Hz (--doppler-center)\n\
         acq_coherent_ms = 1       # acquisition coherent integration, 1 .. 10 ms (--acq-coherent-ms)\n\
         acq_noncoherent = 10      # acquisition non-coherent blocks (--acq-noncoherent)\n\
         # (weak signals, below about 35 dB-Hz: acq_coherent_ms = 10, acq_noncoherent = 10 or more)\n\
         acq_pfa = 1e-5            # probability that an absent PRN is reported, over the whole run (--acq-pfa)\n\
         search_budget_s = 0.005   # CPU s the background search may spend per s of signal; 0: off (--search-budget)\n\
         defer_deep_search_from = 8  # satellites tracked from which an unpredicted PRN's first 10 ms x 50 search waits 5 min; 33: never (--defer-deep-search)\n\
         allow_unhealthy = false   # use satellites flagged unhealthy (--allow-unhealthy)\n\
         outage_bridge = true      # without --ins, carry the channels through an outage under dynamics on the motion of the last fixes\n\
         plots = true              # draw track.png, skyplot.png, cn0.png, dop.png (dr.png with --dr) (--no-plots)\n\
         # approx_time = {{ week = 2190, tow_s = 538200.0 }}  # approximate GPS time of the first sample (--time)\n\
         # approx_llh = [37.5665, 126.978, 40.0]           # approximate position, deg, deg, m (--approx-llh)\n\
         \n\
         [dr]                      # gpsrx run --dr / --accel (seed 000 sensor model)\n\
         sf_g_dps_per_v = 45.045   # nominal gyro scale factor Sf_G, deg/s/V\n\
         v_nom_v = 2.5             # nominal gyro zero-rate voltage V_nom, V\n\
         sf_n_m_per_pulse = 0.1    # nominal odometer scale factor Sf_N, m/pulse\n\
         filter = \"proposed\"       # proposed (8 states, carrier velocity) or conventional (--dr-filter)\n\
         update_interval_s = 1.0   # least interval between GNSS updates of the filters, s\n",
        c.min_pull_in_s,
        c.fll_assist_s,
        c.cn0_lost_dbhz,
        c.vector_cn0_lost_dbhz,
        c.cn0_window_s,
        c.lost_estimates,
        c.relock_after_s,
        c.recover_s,
        c.weak_enter_dbhz,
        c.weak_leave_dbhz,
        enum_name(&c.correlator)?,
        enum_name(&c.correlator_arithmetic)?,
        loops("pull_in", &c.pull_in)?,
        loops("track", &c.track)?,
        loops("weak_track", &c.weak_track.unwrap_or(c.track))?,
        loops(
            "vector_weak_track",
            &c.vector_weak_track.or(c.weak_track).unwrap_or(c.track)
        )?,
        w.enter_dbhz,
        w.fll_assist_s,
        w.bit_sync_dbhz,
        w.p_false_sync,
        w.lost_dbhz,
        w.patience_s,
        loops("weak_pull_in.fll", &w.fll)?,
        loops("weak_pull_in.pll", &w.pll)?,
    );
    let v = gpsrx_receiver::config::VectorSettings::default();
    let vector = format!(
        "\n[vector]                  # the navigation filter of vector tracking ([tracking] mode = \"vector\")\n\
         accel_psd_m2_s3 = {:?}    # white-noise acceleration PSD per ECEF axis, m^2/s^3 (static: 0.1; a 10 g turn: 1000)\n\
         clock_h0 = {:e}          # receiver oscillator white frequency noise h0, s (a TCXO)\n\
         clock_h_2 = {:e}         # receiver oscillator random-walk frequency noise h-2, 1/s (a TCXO)\n\
         gate_pfa = {:?}          # false-alarm probability of the innovation test that excludes a channel\n\
         max_coast_s = {:?}         # longest prediction of a satellite without a measurement that holds its channel through an outage, s\n\
         ins_accel_psd_m2_s3 = {:?} # with --ins: the INS velocity error's random-walk PSD per ECEF axis, m^2/s^3 (the INS's motion drives the filter)\n",
        v.accel_psd_m2_s3, v.clock_h0, v.clock_h_2, v.gate_pfa, v.max_coast_s, v.ins_accel_psd_m2_s3,
    );
    Ok(text + &vector)
}

fn enum_name<T: serde::Serialize>(v: &T) -> anyhow::Result<String> {
    Ok(serde_json::to_value(v)?
        .as_str()
        .unwrap_or_default()
        .to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_default_file_parses_back_to_the_defaults() {
        let text = default_toml().unwrap_or_else(|e| panic!("{e}"));
        let f = gpsrx_receiver::ReceiverConfig::from_toml(&text, "default")
            .unwrap_or_else(|e| panic!("{e}\n{text}"));
        // Every value the file writes is the library's default.
        let defaults = gpsrx_receiver::ReceiverConfig::default();
        assert_eq!(f.tracking, ChannelConfig::default());
        assert_eq!(f.run, defaults.run);
        assert_eq!(f.vector, defaults.vector);
        let nominal = gpsrx_ins_aiding::DrParams::default();
        assert_eq!(f.dr.sf_g_dps_per_v, Some(nominal.sf_g_dps_per_v));
        assert_eq!(f.dr.v_nom_v, Some(nominal.v_nom_v));
        assert_eq!(f.dr.sf_n_m_per_pulse, Some(nominal.sf_n_m_per_pulse));
        assert_eq!(f.dr.filter.as_deref(), Some("proposed"));
    }
}
