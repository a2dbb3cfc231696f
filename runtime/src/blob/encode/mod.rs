//! Writing policy blobs (feature `encode`, host tools; needs `alloc`): owned sections whose
//! constructors lay out and quantize the tables, and [`encode`], which serializes a
//! [`Payload`] (header + postcard) and checks the result with [`Blob::parse`] before returning
//! it, so a blob that leaves a host tool is one the device accepts (a violation is a packer
//! bug, reported as [`EncodeError::Invalid`] with the reader's typed error).
//!
//! The owned sections borrow into the same wire structs the reader decodes
//! ([`OwnedPayload::payload`]), and every table is quantized by [`Quantization`](crate::blob::Quantization), so the
//! writer and the reader share one definition of every byte.
//!
//! - `error`: [`EncodeError`] and the integer-fit checks;
//! - `tables`: the quantized tables ([`OwnedInference`], [`OwnedPolicy`], [`OwnedStyles`],
//!   [`OwnedLabels`]);
//! - `motion`: the library's frames, the rig and the skeleton ([`OwnedLibrary`],
//!   [`OwnedRig`], [`OwnedSkeleton`]);
//! - here: the whole payload ([`OwnedPayload`]) and [`encode`].

mod error;
mod motion;
mod tables;

use alloc::vec::Vec;

pub use error::EncodeError;
pub use motion::{JointSpec, OwnedLibrary, OwnedRig, OwnedSkeleton, SegmentSpec};
pub use tables::{
    LabelsInput, OwnedInference, OwnedLabels, OwnedPolicy, OwnedStyles, PolicyInput, QTable,
};

use crate::blob::header::Header;
use crate::blob::payload::*;
use crate::blob::view::Blob;
use crate::follow::VoiceFollow;
use crate::inference::GmmComponent;
use crate::policy::DecisionTiming;
use crate::policy::Variety;
use crate::prosody::ProsodyConfig;
use crate::rig::ChannelCal;

/// Everything a blob holds, owned.
#[derive(Clone, Debug, PartialEq)]
pub struct OwnedPayload {
    /// Front-end settings.
    pub front_end: FrontEndSection,
    /// Inference layer.
    pub inference: OwnedInference,
    /// Control layer.
    pub policy: OwnedPolicy,
    /// Controller settings.
    pub control: ControlSection,
    /// Gesture library.
    pub library: OwnedLibrary,
    /// Output rig.
    pub rig: OwnedRig,
    /// The library's skeleton (optional, host-side).
    pub skeleton: Option<OwnedSkeleton>,
    /// Tones (optional).
    pub styles: Option<OwnedStyles>,
    /// Semantic labels (optional).
    pub labels: Option<OwnedLabels>,
}

impl OwnedPayload {
    /// The wire form, borrowing from `self`.
    pub fn payload(&self) -> Payload<'_> {
        Payload {
            front_end: self.front_end,
            inference: self.inference.section(),
            policy: self.policy.section(),
            control: self.control,
            library: self.library.section(),
            rig: self.rig.section(),
            skeleton: self.skeleton.as_ref().map(OwnedSkeleton::section),
            styles: self.styles.as_ref().map(OwnedStyles::section),
            labels: self.labels.as_ref().map(OwnedLabels::section),
        }
    }

    /// The blob's bytes ([`encode`] of [`payload`](Self::payload)).
    pub fn encode(&self) -> Result<Vec<u8>, EncodeError> {
        encode(&self.payload())
    }

    /// A small valid payload (2 states, 1 cluster, 2 segments of 3 frames, one hobby-servo
    /// channel) for tests and examples.
    pub fn example() -> Self {
        let gmm = GmmComponent {
            log_voiced: -0.5,
            log_unvoiced: -1.0,
            inv_chol: [1.0, 0.0, 1.0],
            log_norm: -1.8,
            inv_sd: 2.0,
            ..GmmComponent::default()
        };
        let frames: Vec<Vec<f32>> = [0.0, 10.0, 20.0, 20.0, 0.0, -20.0]
            .iter()
            .map(|&v| alloc::vec![v])
            .collect();
        let seg = |start, stroke, label| SegmentSpec {
            start,
            len: 3,
            stroke,
            label,
            continues: false,
        };
        let policy = OwnedPolicy::new(&PolicyInput {
            states: 2,
            segments: 2,
            discount: 0.9,
            u: &[5.0, 10.0, 15.0, 20.0],
            u_cont: &[0.25, 0.5, 0.75, 1.0, 1.25, 1.5],
            exits: &[(0, 2), (1, 1), (1, 2)],
            successors: &[
                alloc::vec![(0, 0.5), (1, -0.5)],
                alloc::vec![],
                alloc::vec![(0, 0.7), (1, 0.0)],
            ],
        });
        let inference =
            OwnedInference::new(&[gmm], 1, &[1.0, -1.0], &[1.0, 0.0, 0.0, 1.0], &[1.0, -1.0]);
        let library = OwnedLibrary::new(
            30.0,
            1,
            &frames,
            &[seg(0, None, 0), seg(3, Some(1), 2)],
            &[],
            &[],
        );
        let rig = OwnedRig::new("example", 20_000.0, &[("head".into(), ChannelCal::HOBBY)]);
        match (inference, policy, library, rig) {
            (Ok(inference), Ok(policy), Ok(library), Ok(rig)) => Self {
                front_end: FrontEndSection::from_config(&ProsodyConfig::DEFAULT),
                inference,
                policy,
                control: ControlSection::new(
                    &DecisionTiming::DEFAULT,
                    &Variety::NONE,
                    &VoiceFollow::NONE,
                    0,
                ),
                library,
                rig,
                skeleton: None,
                styles: None,
                labels: None,
            },
            _ => unreachable!("the example's fixed tables fit their fields"),
        }
    }
}

/// The blob's bytes: header + postcard payload, checked with the runtime's [`Blob::parse`].
pub fn encode(payload: &Payload<'_>) -> Result<Vec<u8>, EncodeError> {
    let body = postcard::to_allocvec(payload).map_err(|_| EncodeError::Encode)?;
    let header = Header::for_payload(&body).ok_or(EncodeError::TooLarge {
        what: "payload bytes",
        value: body.len(),
        ty: "u32",
    })?;
    let mut out = Vec::with_capacity(body.len() + 16);
    out.extend_from_slice(&header.to_bytes());
    out.extend_from_slice(&body);
    Blob::parse(&out).map_err(EncodeError::Invalid)?;
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn example_encodes_and_loads() {
        let p = OwnedPayload::example();
        let bytes = p.encode().unwrap();
        let b = Blob::parse(&bytes).unwrap();
        assert_eq!(*b.payload(), p.payload());
        assert_eq!((b.states(), b.segments(), b.channels()), (2, 2, 1));
        // Quantized values come back within half a step.
        assert!((b.u(1, 1) - 20.0).abs() <= 0.5 * 20.0 / 32767.0 + 1e-6);
        let s = b.successor(0, 1).unwrap();
        assert!((s.cost + 0.5).abs() < 1e-4);
    }
}
