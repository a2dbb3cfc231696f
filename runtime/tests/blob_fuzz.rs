//! The policy blob under mutation: twenty thousand corrupted copies of the tiny blob never
//! make the reader or an accessor panic, and in-range lookups stay finite.

mod common;

use common::*;
use gesture_runtime::blob::*;

/// A deterministic LCG (Knuth's MMIX constants).
struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> u64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        self.0 >> 33
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

/// Calls every accessor with in- and out-of-range indices; nothing may panic and the values of
/// in-range lookups must be finite.
fn exercise(b: &Blob<'_>, rng: &mut Lcg) {
    let fin = |v: f32| assert!(v.is_finite(), "{v}");
    let _ = (
        b.header(),
        b.section_sizes(),
        b.prosody_config(),
        b.payload(),
    );
    for c in b.gmm().as_slice() {
        fin(c.log_norm);
    }
    let _ = b.gmm_component(rng.below(20));
    let crf = b.crf_weights();
    for i in 0..crf.states {
        fin(crf.init.get(i));
    }
    for _ in 0..8 {
        let seg = rng.below(b.segments() + 2);
        let e = rng.below(b.exit_points() + 2);
        let s = rng.below(40);
        fin(b.u(seg, s));
        fin(b.u_cont(e, s));
        b.successors(e).for_each(|x| fin(x.cost));
        let _ = (b.exit(e), b.exit_is_end(e), b.exits_of(seg), b.segment(seg));
        if let Some(x) = b.exit(e) {
            assert_eq!(b.find_exit(x.segment, x.frame), Some(e));
        }
        fin(b.frame(rng.below(40), rng.below(b.frames() + 2)));
        fin(b.segment_value(seg, rng.below(10), rng.below(3)));
        let mut pose = [0.0f32; MAX_CHANNELS];
        b.pose(rng.below(b.frames() + 2), &mut pose);
        pose.iter().for_each(|&v| fin(v));
        let _ = (b.calibration(rng.below(40)), b.channel_name(rng.below(40)));
        if let Some(sk) = b.skeleton() {
            let j = rng.below(sk.joints() + 2);
            let _ = (
                sk.joint_name(j),
                sk.parent(j),
                sk.end_site(j),
                sk.drive(rng.below(4)),
            );
            sk.offset(j).iter().for_each(|&v| fin(v));
            for i in sk.joint_channels(j) {
                fin(sk.rest(i));
                assert!(sk.channel(i).is_some());
            }
            if let Some(p) = sk.parent(j) {
                assert!(p < j);
            }
        }
    }
    for seg in 0..b.segments() {
        // Every segment ends in an exit with a successor (validated).
        let r = b.exits_of(seg);
        assert!(!r.is_empty());
        assert!(b.exit_is_end(r.end - 1));
        assert!(b.successors(r.end - 1).len() > 0);
    }
    for e in [usize::MAX, usize::MAX / 2, usize::MAX / 4 + 1] {
        fin(b.u(e, 0) + b.u_cont(e, 1) + b.frame(0, e) + b.segment_value(e, e, 0));
        let _ = (b.exit(e), b.successors(e).len(), b.segment(e));
    }
}

#[test]
fn twenty_thousand_mutations_never_panic() {
    let good = Tiny::new().encode();
    let mut rng = Lcg(0x5EED_B10B);
    let mut outcomes = std::collections::BTreeMap::<&str, usize>::new();
    for i in 0..20_000 {
        let mut b = good.clone();
        match rng.below(4) {
            // Flip a few bits.
            0 | 1 => {
                for _ in 0..1 + rng.below(4) {
                    let j = rng.below(b.len());
                    b[j] ^= 1 << rng.below(8);
                }
            }
            // Overwrite a byte with an extreme value.
            2 => {
                let j = rng.below(b.len());
                b[j] = [0, 0xFF, 0x7F, 0x80][rng.below(4)];
            }
            // Truncate or extend.
            _ => {
                let n = rng.below(b.len() + 8);
                b.resize(n, rng.below(256) as u8);
            }
        }
        // Most mutations should reach the decoder and validator, not stop at the CRC.
        if i % 4 != 0 {
            fix_crc(&mut b);
        }
        match Blob::parse(&b) {
            Ok(blob) => {
                exercise(&blob, &mut rng);
                *outcomes.entry("ok").or_default() += 1;
            }
            Err(e) => {
                let _ = e.to_string();
                *outcomes.entry(variant(&e)).or_default() += 1;
            }
        }
    }
    eprintln!("{outcomes:?}");
    // The fuzz reaches deep: successes and field-level errors both occur.
    assert!(
        outcomes.get("ok").copied().unwrap_or(0) > 100,
        "{outcomes:?}"
    );
    assert!(outcomes.len() > 15, "{outcomes:?}");
}

#[test]
fn the_valid_tiny_blob_exercises_cleanly() {
    let good = Tiny::new().encode();
    let blob = Blob::parse(&good).unwrap();
    exercise(&blob, &mut Lcg(1));
}
