//! Semantic labels in the controller: a pushed label is answered by the segment carrying it,
//! entered at its entry frame before the stroke, and served when the stroke plays; labels
//! wait in a fixed queue; a labelled blob given no label decides as the same blob without
//! labels; unknown labels are refused.

mod common;

use common::*;
use gesture_runtime::blob::Blob;
use gesture_runtime::controller::{
    BlobController, ControllerEvent, LabelError, LabelOutcome, LABEL_QUEUE,
};
use gesture_runtime::policy::Choice;

/// Samples of a 150 Hz tone with a 4 Hz syllable rhythm (onsets), at 16 kHz.
fn speech(seconds: f64) -> Vec<i16> {
    (0..(seconds * 16_000.0) as usize)
        .map(|i| {
            let t = i as f64 / 16_000.0;
            let env = (0.5 + 0.5 * (2.0 * std::f64::consts::PI * 4.0 * t).sin()).powi(2);
            (8000.0 * env * (2.0 * std::f64::consts::PI * 150.0 * t).sin()) as i16
        })
        .collect()
}

#[derive(Debug, PartialEq)]
enum Rec {
    Decision(u64, usize, Choice, usize),
    Label(u64, usize, LabelOutcome),
}

fn run(bytes: &[u8], labels: &[(usize, usize)]) -> (Vec<Rec>, Vec<(usize, usize)>) {
    let blob = Blob::parse(bytes).unwrap();
    let mut c = BlobController::from_blob(&blob).unwrap();
    let samples = speech(4.0);
    let mut out = Vec::new();
    let mut shown = Vec::new();
    let mut at = 0;
    for &(sample, label) in labels {
        c.push(&samples[at..sample], &mut |e| {
            record(e, &mut out, &mut shown)
        });
        c.push_label(label).unwrap();
        at = sample;
    }
    c.push(&samples[at..], &mut |e| record(e, &mut out, &mut shown));
    (out, shown)
}

fn record(e: ControllerEvent<'_>, out: &mut Vec<Rec>, shown: &mut Vec<(usize, usize)>) {
    match e {
        ControllerEvent::Decision { tick, decision } => out.push(Rec::Decision(
            tick,
            decision.exit,
            decision.choice,
            decision.entry_frame,
        )),
        ControllerEvent::Label {
            tick,
            label,
            outcome,
        } => out.push(Rec::Label(tick, label, outcome)),
        ControllerEvent::Pose { segment, frame, .. } => shown.push((segment, frame)),
        _ => {}
    }
}

fn labelled() -> Vec<u8> {
    let mut t = Tiny::new();
    t.label_section = Some(TinyLabels::one());
    t.encode()
}

#[test]
fn a_label_is_answered_before_its_stroke_and_served_when_it_plays() {
    let bytes = labelled();
    // Label 1 (`bye`, carried by segment 1 with its stroke at frame 1) at 1 s.
    let (out, shown) = run(&bytes, &[(16_000, 1)]);
    let labels: Vec<&Rec> = out.iter().filter(|r| matches!(r, Rec::Label(..))).collect();
    assert!(
        matches!(labels[0], Rec::Label(31, 1, LabelOutcome::Received)),
        "{labels:?}"
    );
    let Rec::Label(entered_at, 1, LabelOutcome::Entered { segment: 1, frame }) = *labels[1] else {
        panic!("{labels:?}");
    };
    assert!(frame <= 1, "entered at frame {frame}, after the stroke");
    let Rec::Label(stroke_at, 1, LabelOutcome::Stroke) = *labels[2] else {
        panic!("{labels:?}");
    };
    // The stroke is shown: segment 1's frame 1 is on screen at the stroke's tick.
    assert_eq!(shown[stroke_at as usize], (1, 1));
    assert!(
        stroke_at >= entered_at && stroke_at - 31 <= 10,
        "{entered_at} -> {stroke_at}"
    );
}

#[test]
fn no_label_decides_as_the_blob_without_labels() {
    let plain = Tiny::new().encode();
    let (a, sa) = run(&plain, &[]);
    let (b, sb) = run(&labelled(), &[]);
    assert!(!a.is_empty());
    assert_eq!(a, b);
    assert_eq!(sa, sb);
}

#[test]
fn labels_queue_and_unknown_ones_are_refused() {
    let bytes = labelled();
    let blob = Blob::parse(&bytes).unwrap();
    let mut c = BlobController::from_blob(&blob).unwrap();
    assert_eq!(
        c.push_label(2),
        Err(LabelError::Unknown {
            label: 2,
            labels: 2
        })
    );
    c.push_label(0).unwrap();
    assert_eq!(c.active_label(), Some(0));
    for _ in 0..LABEL_QUEUE {
        c.push_label(1).unwrap();
    }
    assert_eq!(c.push_label(1), Err(LabelError::QueueFull));
    c.clear_labels();
    assert_eq!(c.active_label(), None);
    // `hello` has no segment: it times out after 2 s and the next one is served.
    c.push_label(0).unwrap();
    c.push_label(1).unwrap();
    let mut events = Vec::new();
    c.push(&speech(4.0), &mut |e| {
        if let ControllerEvent::Label {
            tick,
            label,
            outcome,
        } = e
        {
            events.push((tick, label, outcome));
        }
    });
    let timed_out = events
        .iter()
        .find(|e| e.2 == LabelOutcome::TimedOut)
        .unwrap();
    assert_eq!((timed_out.0, timed_out.1), (60, 0), "{events:?}");
    assert!(events
        .iter()
        .any(|e| e.1 == 1 && e.2 == LabelOutcome::Stroke));
    // A blob without labels refuses every label.
    let plain = Tiny::new().encode();
    let blob = Blob::parse(&plain).unwrap();
    let mut c = BlobController::from_blob(&blob).unwrap();
    assert!(matches!(c.push_label(0), Err(LabelError::Unknown { .. })));
}

#[test]
fn a_label_asked_for_while_the_body_rests_is_answered_at_once() {
    // One second of speech, then three of silence: the body rests (the blob rests after
    // 750 ms, segment 0 is its calmest). `bye` (segment 1) is asked for 1.5 s into the
    // silence, at tick 75 (30 fps): it is entered within two ticks, not when the speech
    // returns or the label times out.
    let bytes = labelled();
    let blob = Blob::parse(&bytes).unwrap();
    let mut c = BlobController::from_blob(&blob).unwrap();
    let mut samples = speech(1.0);
    samples.resize(4 * 16_000, 0);
    let mut out = Vec::new();
    let mut shown = Vec::new();
    c.push(&samples[..40_000], &mut |e| record(e, &mut out, &mut shown));
    assert_eq!(shown.last().map(|s| s.0), Some(0), "resting in segment 0");
    let asked = shown.len() as u64;
    c.push_label(1).unwrap();
    c.push(&samples[40_000..], &mut |e| record(e, &mut out, &mut shown));
    let entered = out.iter().find_map(|r| match *r {
        Rec::Label(t, 1, LabelOutcome::Entered { segment: 1, .. }) => Some(t),
        _ => None,
    });
    let entered = entered.unwrap_or_else(|| panic!("never entered: {out:?}"));
    assert!(
        entered >= asked && entered - asked <= 2,
        "asked at tick {asked}, entered at {entered}"
    );
    assert!(out
        .iter()
        .any(|r| matches!(r, Rec::Label(_, 1, LabelOutcome::Stroke))));
}
