//! Style control: tone weights mix the value tables linearly, the neutral style is the
//! unstyled policy, and bad weights are refused with a typed error.

mod common;

use common::*;
use gesture_runtime::blob::Blob;
use gesture_runtime::policy::{
    select, select_styled, Choice, Penalties, PolicyTables, Style, StyleError,
};

fn styled_bytes() -> Vec<u8> {
    let mut t = Tiny::new();
    // 2 segments x 2 states of U, 3 exits x 2 states of U_cont.
    t.styles = Some(TinyStyles::two(4, 6));
    t.encode()
}

/// The expected cost of entering `c` from exit `e` under `b`, with the tables mixed by hand.
fn by_hand(blob: &Blob, e: usize, c: usize, b: &[f32], neutral: f32, w: &[f32]) -> f32 {
    let sc = blob
        .successors(e)
        .find(|s| s.segment as usize == c)
        .unwrap()
        .cost;
    let mut v = sc;
    for (s, &bs) in b.iter().enumerate() {
        let mut u = neutral * blob.u(c, s);
        for (m, &wm) in w.iter().enumerate() {
            u += wm * blob.tone_u(m, c, s);
        }
        v += bs * u;
    }
    v
}

#[test]
fn a_mix_of_tones_is_the_linear_mix_of_their_tables() {
    let bytes = styled_bytes();
    let blob = Blob::parse(&bytes).unwrap();
    assert_eq!(PolicyTables::tones(&blob), 2);
    let b = [0.3f32, 0.7];
    // Exit 0 ends segment 0; its successors are segments 0 and 1.
    for (neutral, w) in [
        (1.0f32, [0.0f32, 0.0]),
        (0.0, [1.0, 0.0]),
        (0.0, [0.0, 1.0]),
        (0.25, [0.25, 0.5]),
        (0.5, [0.5, 0.0]),
    ] {
        let style = Style::new(&w).unwrap();
        assert!((style.neutral() - neutral).abs() < 1e-6);
        let d = select_styled(&blob, 0, &b, &Penalties::NONE, &style);
        let costs: Vec<f32> = (0..2)
            .map(|c| by_hand(&blob, 0, c, &b, neutral, &w))
            .collect();
        let best = if costs[0] <= costs[1] { 0 } else { 1 };
        assert_eq!(d.choice, Choice::Enter(best), "{w:?}: {costs:?}");
        assert!(
            (d.cost - costs[best]).abs() < 1e-4,
            "{} vs {}",
            d.cost,
            costs[best]
        );
    }
    // Linear: the cost of a candidate under a mix is the mix of its costs under each tone
    // (weights summing to 1). Known values: U^calm(1) = (3, 4), U^lively(1) = (-3, -4),
    // U(1) = (15, 20), S(0, 1) = -0.5: calm 3.7 - 0.5, lively -3.7 - 0.5, neutral 18.5 - 0.5.
    let one = |w: &[f32]| by_hand(&blob, 0, 1, &b, 1.0 - w.iter().sum::<f32>(), w);
    assert!((one(&[1.0, 0.0]) - 3.2).abs() < 1e-3);
    assert!((one(&[0.0, 1.0]) + 4.2).abs() < 1e-3);
    assert!((one(&[0.0, 0.0]) - 18.0).abs() < 1e-3);
    // Under lively the cheap segment is 1 (-4.2 against U^lively(0) = (-1, -2): -1.7 + 0.5).
    let d = select_styled(
        &blob,
        0,
        &b,
        &Penalties::NONE,
        &Style::new(&[0.0, 1.0]).unwrap(),
    );
    assert_eq!(d.choice, Choice::Enter(1));
    assert!((d.cost + 4.2).abs() < 1e-3, "{}", d.cost);
    // Continuing at the interruption exit 1 mixes U_cont the same way: U_cont^calm(1) =
    // (3, 4) * 0.5, neutral (0.75, 1.0).
    let d = select_styled(&blob, 1, &b, &Penalties::NONE, &Style::new(&[0.5]).unwrap());
    let cont = 0.5 * (0.3 * 0.75 + 0.7 * 1.0) + 0.5 * (0.3 * 1.5 + 0.7 * 2.0);
    assert_eq!(d.choice, Choice::Continue);
    assert!((d.cost - cont).abs() < 1e-4, "{} vs {cont}", d.cost);
}

#[test]
fn the_neutral_style_is_the_unstyled_policy() {
    let styled = styled_bytes();
    let plain = Tiny::new().encode();
    let (a, p) = (Blob::parse(&styled).unwrap(), Blob::parse(&plain).unwrap());
    for e in 0..3 {
        for b in [[1.0f32, 0.0], [0.5, 0.5], [0.1, 0.9]] {
            let x = select_styled(&a, e, &b, &Penalties::NONE, &Style::NEUTRAL);
            let y = select(&p, e, &b, &Penalties::NONE);
            assert_eq!(x, y);
            // All-zero weights are the neutral style.
            let z = select_styled(
                &a,
                e,
                &b,
                &Penalties::NONE,
                &Style::new(&[0.0, 0.0]).unwrap(),
            );
            assert_eq!(z, y);
        }
    }
}

#[test]
fn weights_are_validated_and_normalized() {
    assert_eq!(
        Style::new(&[0.5, f32::NAN]),
        Err(StyleError::NotFinite { tone: 1 })
    );
    assert_eq!(
        Style::new(&[f32::INFINITY]),
        Err(StyleError::NotFinite { tone: 0 })
    );
    assert_eq!(Style::new(&[-0.1]), Err(StyleError::Negative { tone: 0 }));
    assert!(matches!(
        Style::new(&[0.1; 9]),
        Err(StyleError::TooManyWeights { given: 9, .. })
    ));
    // Over 1: divided by the sum, nothing left for neutral.
    let s = Style::new(&[3.0, 1.0]).unwrap();
    assert_eq!((s.neutral(), s.weights()), (0.0, &[0.75f32, 0.25][..]));
    let s = Style::new(&[0.2, 0.3]).unwrap();
    assert!((s.neutral() - 0.5).abs() < 1e-6);
    let s = Style::new(&[f32::MAX, f32::MAX]).unwrap();
    assert_eq!(s.weights(), &[0.5, 0.5]);
    assert!(Style::new(&[]).unwrap().is_neutral());
    // Every message is one line.
    for e in [
        StyleError::NotFinite { tone: 1 },
        StyleError::Negative { tone: 0 },
        StyleError::TooManyWeights { given: 3, tones: 2 },
    ] {
        let m = e.to_string();
        assert!(!m.is_empty() && !m.contains('\n'));
    }
}

#[test]
fn the_controller_takes_a_style_for_its_tables_only() {
    let styled = styled_bytes();
    let blob = Blob::parse(&styled).unwrap();
    let mut c = gesture_runtime::controller::BlobController::from_blob(&blob).unwrap();
    assert!(c.style().is_neutral());
    assert_eq!(
        c.set_style(&[0.5, 0.2, 0.1]),
        Err(StyleError::TooManyWeights { given: 3, tones: 2 })
    );
    assert_eq!(
        c.set_style(&[0.5, -1.0]),
        Err(StyleError::Negative { tone: 1 })
    );
    assert!(
        c.style().is_neutral(),
        "a refused style keeps the one in force"
    );
    c.set_style(&[0.0, 1.0]).unwrap();
    assert_eq!(c.style().weights(), &[0.0, 1.0]);
    let plain = Tiny::new().encode();
    let blob = Blob::parse(&plain).unwrap();
    let mut c = gesture_runtime::controller::BlobController::from_blob(&blob).unwrap();
    assert!(c.set_style(&[1.0]).is_err());
    assert!(c.set_style(&[]).is_ok());
}

/// The blob reads a row of a value table at once; the number is bit for bit the per-state sum
/// (so the selector's costs did not change with it).
#[test]
fn row_dot_products_equal_the_per_state_sums() {
    let bytes = styled_bytes();
    let blob = Blob::parse(&bytes).unwrap();
    let b = [0.3f32, 0.7];
    let sum =
        |f: &dyn Fn(usize) -> f32| b.iter().enumerate().fold(0.0f32, |a, (s, &w)| a + w * f(s));
    for c in 0..2 {
        assert_eq!(blob.u_dot(c, &b), sum(&|s| blob.u(c, s)));
        for m in 0..2 {
            assert_eq!(blob.tone_u_dot(m, c, &b), sum(&|s| blob.tone_u(m, c, s)));
        }
    }
    for e in 0..3 {
        assert_eq!(blob.u_cont_dot(e, &b), sum(&|s| blob.u_cont(e, s)));
        for m in 0..2 {
            assert_eq!(
                blob.tone_u_cont_dot(m, e, &b),
                sum(&|s| blob.tone_u_cont(m, e, s))
            );
        }
    }
    // Out of range reads 0; a longer belief is cut to the states.
    assert_eq!(blob.u_dot(2, &b), 0.0);
    assert_eq!(blob.tone_u_dot(2, 0, &b), 0.0);
    assert_eq!(blob.u_dot(1, &[0.3, 0.7, 5.0]), blob.u_dot(1, &b));
}
