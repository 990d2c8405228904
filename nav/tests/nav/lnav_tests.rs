//! LNAV message: parity against the published parity matrix, encoder -> decoder -> assembler
//! round trip for every ephemeris of brdc0010.22n, single-bit-error detection, polarity, HOW.

use crate::common::brdc;
use gpsrx_nav::lnav::fields::{self as fd, Field};
use gpsrx_nav::lnav::{
    decode_subframe, decode_subframe_any_polarity, decode_tlm_how, is_inverted_preamble,
    parity_bits, parity_check, parity_encode, DecodedSubframe, EphemerisAssembler, LnavEncoder,
    LnavError, Polarity, Sf4Page25, SubframePayload,
};
use gpsrx_nav::{Ephemeris, GpsTime, KlobucharParams, UtcParams};

/// Parity matrix H of the (32,26) Hamming code as printed in Tsui, "Fundamentals of Global
/// Positioning System Receivers", eq. 5.3 (rows D25..D30, columns d1..d24), transcribed
/// independently of IS-GPS-200 Table 20-XIV that the implementation encodes.
const TSUI_H: [&str; 6] = [
    "111011000111110011010010",
    "011101100011111001101001",
    "101110110001111100110100",
    "010111011000111110011010",
    "101011101100011111001101",
    "001011011110101000100111",
];

#[test]
fn parity_matches_published_matrix() {
    for (i, _) in (1..=24).enumerate() {
        let p = parity_bits(1 << (23 - i), false, false);
        for (row, h) in TSUI_H.iter().enumerate() {
            let expected = u32::from(h.as_bytes()[i] == b'1');
            assert_eq!(
                (p >> (5 - row)) & 1,
                expected,
                "d{} in D{}",
                i + 1,
                25 + row
            );
        }
    }
    // D29* seeds D25, D27, D30; D30* seeds D26, D28, D29 (Table 20-XIV).
    assert_eq!(parity_bits(0, true, false), 0b101001);
    assert_eq!(parity_bits(0, false, true), 0b010110);
}

#[test]
fn complement_when_previous_d30_is_one() {
    let data = 0x8B_1234;
    let w = parity_encode(data, false, true);
    assert_eq!(
        w >> 6,
        !data & 0xFF_FFFF,
        "data bits complemented when D30* = 1"
    );
    assert_eq!(parity_check(w, false, true), Some(data));
    assert_eq!(parity_encode(data, false, false) >> 6, data);
    // The same transmitted word read with the wrong D30* fails.
    assert_eq!(parity_check(w, false, false), None);
}

/// Example Klobuchar/UTC sets (the brdc0010.22n header values).
pub(crate) fn iono_utc() -> (KlobucharParams, UtcParams) {
    let nav = brdc();
    (nav.iono.expect("iono"), nav.utc.expect("utc"))
}

/// Transmitted subframes 1-3 of `enc` starting at the frame boundary ~1 h before toe.
pub(crate) fn frame_start(eph: &Ephemeris) -> GpsTime {
    let tx = eph.toe.add_seconds(-3600.0);
    GpsTime::new(tx.week, f64::from((tx.tow_s as u32) / 30 * 30))
}

fn decode_stream(enc: &LnavEncoder, start: GpsTime, n: u32) -> Vec<DecodedSubframe> {
    let mut prev = (false, false);
    (0..n)
        .map(|k| {
            let t = start.add_seconds(6.0 * f64::from(k));
            let bits = enc.subframe_bits(t.tow_s as u32, t.week);
            let sf = decode_subframe(&bits, prev.0, prev.1).expect("valid subframe");
            prev = sf.last_d29_d30;
            sf
        })
        .collect()
}

fn float_fields(e: &Ephemeris) -> Vec<(Field, f64)> {
    vec![
        (fd::TOC, e.toc.tow_s),
        (fd::AF0, e.af0_s),
        (fd::AF1, e.af1_s_s),
        (fd::AF2, e.af2_s_s2),
        (fd::TGD, e.tgd_s),
        (fd::CRS, e.crs_m),
        (fd::DELTA_N, e.delta_n_rad_s),
        (fd::M0, e.m0_rad),
        (fd::CUC, e.cuc_rad),
        (fd::ECC, e.e),
        (fd::CUS, e.cus_rad),
        (fd::SQRT_A, e.sqrt_a_sqrt_m),
        (fd::TOE, e.toe.tow_s),
        (fd::CIC, e.cic_rad),
        (fd::OMEGA0, e.omega0_rad),
        (fd::CIS, e.cis_rad),
        (fd::I0, e.i0_rad),
        (fd::CRC, e.crc_m),
        (fd::OMEGA, e.omega_rad),
        (fd::OMEGA_DOT, e.omega_dot_rad_s),
        (fd::IDOT, e.idot_rad_s),
    ]
}

#[test]
fn every_brdc_ephemeris_round_trips() {
    let nav = brdc();
    let (iono, utc) = iono_utc();
    let mut worst = 0.0f64; // largest |decoded - original| in units of the field's LSB
    for eph in &nav.ephemerides {
        let enc = LnavEncoder::new(eph, Some(&iono), Some(&utc)).expect("brdc fits the ICD");
        let start = frame_start(eph);
        let mut asm = EphemerisAssembler::new(eph.prn, 2200);
        let mut out = None;
        for sf in decode_stream(&enc, start, 5) {
            if let Some(e) = asm.push(&sf) {
                out = Some(e);
            }
        }
        let dec = out.expect("subframes 1-3 assemble");
        assert_eq!(
            dec,
            eph.quantized_to_icd(),
            "PRN {} toe {:?}",
            eph.prn,
            eph.toe
        );
        assert_eq!(dec.toe.week, eph.toe.week);
        assert_eq!(dec.toc.week, eph.toc.week);
        for ((field, orig), (_, got)) in float_fields(eph).into_iter().zip(float_fields(&dec)) {
            let lsb = field.to_si(1);
            let err = (got - orig).abs() / lsb;
            assert!(
                err <= 0.5 + 1e-9,
                "PRN {} {}: {orig} -> {got}",
                eph.prn,
                field.name
            );
            worst = worst.max(err);
        }
    }
    eprintln!(
        "LNAV round trip of {} ephemerides: worst field error {worst:.4} LSB",
        nav.ephemerides.len()
    );
    // The IGS file was itself decoded from broadcast LNAV, so its values sit on the ICD grid;
    // a field whose LSB we had made coarser than the ICD's would show errors up to 0.5 LSB.
    assert!(worst < 0.01, "brdc values are {worst} LSB off our grid");
}

#[test]
fn page18_round_trips() {
    let (iono, utc) = iono_utc();
    let eph = &brdc().ephemerides[0];
    let enc = LnavEncoder::new(eph, Some(&iono), Some(&utc)).expect("fits");
    // TOW 538218 -> subframe 4.
    let bits = enc.subframe_bits(538_218, 2190);
    let sf = decode_subframe(&bits, false, false).expect("valid");
    assert_eq!(sf.how.subframe_id, 4);
    match sf.payload {
        SubframePayload::Page18 { iono: i, utc: u } => {
            assert_eq!(i, iono.quantized_to_icd());
            for k in 0..4 {
                assert!((i.alpha[k] - iono.alpha[k]).abs() <= fd::ALPHA[k].lsb / 2.0);
                assert!((i.beta[k] - iono.beta[k]).abs() <= fd::BETA[k].lsb / 2.0);
            }
            assert_eq!(u.wnt, 2191 % 256);
            assert_eq!(u.resolve_weeks(2190), utc.quantized_to_icd());
            assert!((u.a0_s - utc.a0_s).abs() <= fd::A0.lsb / 2.0);
            assert!((u.a1_s_s - utc.a1_s_s).abs() <= fd::A1.lsb / 2.0);
            assert_eq!(u.tot_s, 147_456);
            assert_eq!(u.dt_ls_s, 18);
        }
        other => panic!("expected page 18, got {other:?}"),
    }
}

#[test]
fn dummy_pages_without_iono_utc() {
    let eph = &brdc().ephemerides[0];
    let enc = LnavEncoder::new(eph, None, None).expect("fits");
    let sf4 = decode_subframe(&enc.subframe_bits(18, 2190), false, false).expect("valid");
    // A page-25 style page with all data zero (SV ID 63): every SV healthy, configuration 0.
    assert_eq!(
        sf4.payload,
        SubframePayload::Sf4Page25(Sf4Page25 {
            sv_config: [0; 32],
            health6: [0; 8]
        })
    );
    let sf5 = decode_subframe(&enc.subframe_bits(24, 2190), false, false).expect("valid");
    assert_eq!(
        sf5.payload,
        SubframePayload::Other {
            subframe_id: 5,
            data_id: 1,
            sv_id: 0
        }
    );
}

#[test]
fn how_tow_and_subframe_id() {
    let eph = &brdc().ephemerides[0];
    let enc = LnavEncoder::new(eph, None, None).expect("fits");
    for tow in [0u32, 6, 24, 30, 538_200, 538_206, 604_788, 604_794] {
        let sf = decode_subframe(&enc.subframe_bits(tow, 2190), false, false).expect("valid");
        // IS-GPS-200 20.3.3.2: truncated TOW of the next subframe's leading edge.
        assert_eq!(sf.how.tow_count, (tow / 6 + 1) % 100_800, "tow {tow}");
        assert_eq!(u32::from(sf.how.subframe_id), (tow / 6) % 5 + 1);
        assert_eq!(sf.how.subframe_start_tow_s(), tow);
        assert!(!sf.how.alert && !sf.how.anti_spoof);
        // Words 2 and 10 end with D29 = D30 = 0.
        assert_eq!(sf.last_d29_d30, (false, false));
    }
    // Last subframe of the week: count wraps to 0 (next subframe starts the next week).
    let sf = decode_subframe(&enc.subframe_bits(604_794, 2190), false, false).expect("valid");
    assert_eq!(sf.how.tow_count, 0);
    // Week number modulo 1024 in subframe 1.
    let sf = decode_subframe(&enc.subframe_bits(538_200, 2190), false, false).expect("valid");
    match sf.payload {
        SubframePayload::Subframe1(s) => assert_eq!(s.week_mod_1024, 2190 - 2048),
        other => panic!("{other:?}"),
    }
}

#[test]
fn every_single_bit_flip_is_detected() {
    let (iono, utc) = iono_utc();
    let eph = &brdc().ephemerides[5];
    let enc = LnavEncoder::new(eph, Some(&iono), Some(&utc)).expect("fits");
    for sf_start in [538_200u32, 538_206, 538_212, 538_218, 538_224] {
        let bits = enc.subframe_bits(sf_start, 2190);
        decode_subframe(&bits, false, false).expect("clean subframe decodes");
        for pos in 0..300 {
            let mut b = bits;
            b[pos] ^= 1;
            let err = decode_subframe(&b, false, false).expect_err("flip must be detected");
            let word = pos / 30 + 1;
            assert!(
                matches!(err, LnavError::Parity { word: w } if w == word),
                "subframe at {sf_start}, bit {pos}: {err:?}"
            );
        }
    }
}

#[test]
fn complemented_words_appear_in_real_subframes() {
    // Some words follow a word ending in D30 = 1: their data bits go out complemented. Check
    // that the encoder does so by re-deriving every word from its predecessor's last bit.
    let eph = &brdc().ephemerides[0];
    let enc = LnavEncoder::new(eph, None, None).expect("fits");
    let mut complemented = 0;
    for sf_start in (538_200u32..538_230).step_by(6) {
        let bits = enc.subframe_bits(sf_start, 2190);
        let word = |k: usize| {
            bits[30 * k..30 * k + 30]
                .iter()
                .fold(0u32, |a, &b| (a << 1) | u32::from(b))
        };
        for k in 1..10 {
            let prev = word(k - 1);
            let (d29, d30) = (prev & 2 != 0, prev & 1 != 0);
            let data = parity_check(word(k), d29, d30).expect("parity ok");
            if d30 {
                complemented += 1;
                assert_eq!(word(k) >> 6, !data & 0xFF_FFFF);
            } else {
                assert_eq!(word(k) >> 6, data);
            }
        }
    }
    assert!(complemented > 5, "only {complemented} complemented words");
}

#[test]
fn inverted_polarity_is_recognised() {
    let eph = &brdc().ephemerides[0];
    let enc = LnavEncoder::new(eph, None, None).expect("fits");
    let bits = enc.subframe_bits(538_206, 2190);
    let mut inv = bits;
    for b in inv.iter_mut() {
        *b ^= 1;
    }
    assert!(!is_inverted_preamble(&bits));
    assert!(is_inverted_preamble(&inv));
    // Decoded as if normal (previous word assumed (0, 0)): recognised as inverted.
    assert_eq!(
        decode_subframe(&inv, false, false),
        Err(LnavError::InvertedPolarity)
    );
    let normal = decode_subframe(&bits, false, false).expect("normal");
    let (sf, polarity) = decode_subframe_any_polarity(&inv).expect("decodes");
    assert_eq!(polarity, Polarity::Inverted);
    assert_eq!(
        (sf.tlm, sf.how, sf.payload),
        (normal.tlm, normal.how, normal.payload)
    );
    // Received last bits are inverted too; feeding them on keeps decoding the inverted stream.
    assert_eq!(sf.last_d29_d30, (true, true));
    let mut next = enc.subframe_bits(538_212, 2190);
    for b in next.iter_mut() {
        *b ^= 1;
    }
    let n = decode_subframe(&next, true, true).expect("polarity-transparent parity");
    assert_eq!(n.how.subframe_id, 3);
    let (_, polarity) = decode_subframe_any_polarity(&bits).expect("decodes");
    assert_eq!(polarity, Polarity::Normal);
}

#[test]
fn bad_input_is_an_error_not_a_panic() {
    let eph = &brdc().ephemerides[0];
    let enc = LnavEncoder::new(eph, None, None).expect("fits");
    let mut bits = enc.subframe_bits(538_200, 2190);
    bits[17] = 2;
    assert_eq!(
        decode_subframe(&bits, false, false),
        Err(LnavError::NotBinary {
            index: 17,
            value: 2
        })
    );
    let mut bad = eph.clone();
    bad.af0_s = 0.01; // a_f0 holds +-2^21 * 2^-31 s = +-0.98 ms
    let err = LnavEncoder::new(&bad, None, None).expect_err("a_f0 too large");
    assert!(
        matches!(
            err,
            LnavError::FieldRange {
                field: "a_f0",
                prn: 1,
                ..
            }
        ),
        "{err}"
    );
    assert!(err.to_string().contains("a_f0"));
    let mut bad = eph.clone();
    bad.iodc = 1024;
    assert!(LnavEncoder::new(&bad, None, None).is_err());
    let mut bad = eph.clone();
    bad.m0_rad = f64::NAN;
    assert!(LnavEncoder::new(&bad, None, None).is_err());
    // All zeros: parity of an all-zero word is zero, so it fails on the preamble.
    assert!(matches!(
        decode_subframe(&[0u8; 300], false, false),
        Err(LnavError::BadPreamble { found: 0 })
    ));
}

#[test]
fn assembler_requires_matching_issue_of_data_and_resolves_weeks() {
    let nav = brdc();
    // An ephemeris with toe/toc at the start of week 2191, transmitted at the end of week 2190.
    let eph = &Ephemeris {
        toe: GpsTime::new(2191, 0.0),
        toc: GpsTime::new(2191, 0.0),
        ..nav.ephemerides[0].clone()
    };
    let enc = LnavEncoder::new(eph, None, None).expect("fits");
    let start = GpsTime::new(2190, 604_800.0 - 3600.0);
    let sfs = decode_stream(&enc, start, 3);
    let mut asm = EphemerisAssembler::new(eph.prn, 2190 + 300);
    assert!(asm.push(&sfs[0]).is_none());
    assert!(asm.push(&sfs[1]).is_none());
    let e = asm.push(&sfs[2]).expect("complete set");
    assert_eq!(e.toe, GpsTime::new(2191, 0.0));
    assert_eq!(e, eph.quantized_to_icd());
    // Same set again: nothing new.
    assert!(asm.push(&sfs[2]).is_none());

    // Subframe 3 from another issue of data: no ephemeris.
    let mut other = eph.clone();
    other.iode = (eph.iode + 1) % 256;
    let enc2 = LnavEncoder::new(&other, None, None).expect("fits");
    let sf3_other = decode_stream(&enc2, start, 3)[2];
    let mut asm = EphemerisAssembler::new(eph.prn, 2190);
    asm.push(&sfs[0]);
    asm.push(&sfs[1]);
    assert!(asm.push(&sf3_other).is_none());
}

#[test]
fn the_tlm_and_how_alone_give_the_subframe_time_in_either_polarity() {
    let eph = &brdc().ephemerides[0];
    let enc = LnavEncoder::new(eph, None, None).expect("fits");
    // IS-GPS-200 20.3.3.2: the HOW carries the TOW count of the next subframe; the subframe
    // starting at TOW 538218 s is subframe 4 ((538218 / 6) mod 5 = 3 -> ID 4).
    let bits = enc.subframe_bits(538_218, 2190);
    let (how, pol) = decode_tlm_how(&bits[..60]).expect("TLM and HOW check");
    assert_eq!(how.subframe_start_tow_s(), 538_218);
    assert_eq!(how.subframe_id, 4);
    assert_eq!(pol, Polarity::Normal);
    let inverted: Vec<u8> = bits[..60].iter().map(|b| 1 - b).collect();
    let (how_inv, pol_inv) = decode_tlm_how(&inverted).expect("inverted checks too");
    assert_eq!(how_inv, how);
    assert_eq!(pol_inv, Polarity::Inverted);
    // One bit flipped in the HOW fails its parity; 59 bits are not enough.
    let mut bad = bits[..60].to_vec();
    bad[40] ^= 1;
    assert!(decode_tlm_how(&bad).is_none());
    assert!(decode_tlm_how(&bits[..59]).is_none());
    // Shifted by one bit: no preamble.
    assert!(decode_tlm_how(&bits[1..61]).is_none());
}
