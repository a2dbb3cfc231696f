//! Building a controller: from a validated blob (what host tools and boards do) or from
//! tables that need not come from a blob (the runtime's tests), with the build's front-end
//! arithmetic or a chosen one (`prosody::arith`). Everything is built in place
//! (`*_in`), so a board never copies the 15 KiB controller on its stack.

use super::{Controller, ControllerError};
use crate::blob::Blob;
use crate::inference::{CrfWeights, GmmComponent};
use crate::player::LibraryFrames;
use crate::policy::PolicyTables;
use crate::prosody::arith::Arith;
use crate::prosody::ProsodyConfig;

impl<'a> Controller<'a, Blob<'a>, Blob<'a>> {
    /// The controller over a validated blob's tables, with the blob's front-end settings and
    /// decision timing: the one way host tools and boards build a controller.
    ///
    /// The controller is about 15 KiB and is copied on the stack on its way out of here; a
    /// board with little RAM builds it in place with [`from_blob_in`](Self::from_blob_in).
    pub fn from_blob(blob: &'a Blob<'a>) -> Result<Self, ControllerError> {
        Self::from_blob_arith(blob)
    }

    /// [`from_blob`](Self::from_blob), built in place in `slot` (on the caller's stack or in
    /// a `static`) without a temporary copy. On an error `slot` is `None`.
    pub fn from_blob_in<'s>(
        slot: &'s mut Option<Self>,
        blob: &'a Blob<'a>,
    ) -> Result<&'s mut Self, ControllerError> {
        Self::from_blob_arith_in(slot, blob)
    }
}

impl<'a, A: Arith> Controller<'a, Blob<'a>, Blob<'a>, A> {
    /// [`from_blob`](Controller::from_blob) with the front-end arithmetic `A` (host tools
    /// compare the `f32` and the fixed-point controllers on the same blob).
    pub fn from_blob_arith(blob: &'a Blob<'a>) -> Result<Self, ControllerError> {
        let mut slot = None;
        Self::from_blob_arith_in(&mut slot, blob)?;
        slot.ok_or(ControllerError::Dimensions)
    }

    /// [`from_blob_in`](Controller::from_blob_in) with the front-end arithmetic `A`.
    pub fn from_blob_arith_in<'s>(
        slot: &'s mut Option<Self>,
        blob: &'a Blob<'a>,
    ) -> Result<&'s mut Self, ControllerError> {
        let gmm = blob.gmm();
        let config = blob.prosody_config();
        let me = Self::new_arith_in(
            slot,
            &config,
            gmm.as_slice(),
            blob.crf_weights(),
            blob,
            blob,
        )?;
        me.timing = blob.timing();
        me.variety = blob.variety();
        me.label_timeout_ms = blob.label_timeout_ms();
        me.set_follow(blob.follow());
        me.set_blend_ms(blob.blend_ms());
        me.player
            .set_speed_cap(crate::player::library_speed_cap(blob));
        Ok(me)
    }
}

impl<'a, T: PolicyTables + ?Sized, L: LibraryFrames + ?Sized> Controller<'a, T, L> {
    /// A controller at the start of segment 0 with a uniform belief, over tables that need
    /// not come from a blob (the runtime's tests build small ones by hand). Host tools and
    /// boards use [`from_blob`](Controller::from_blob).
    pub fn new(
        config: &ProsodyConfig,
        gmm: &[GmmComponent],
        crf: CrfWeights<'a>,
        tables: &'a T,
        lib: &'a L,
    ) -> Result<Self, ControllerError> {
        let mut slot = None;
        Self::new_arith_in(&mut slot, config, gmm, crf, tables, lib)?;
        slot.ok_or(ControllerError::Dimensions)
    }

    /// The controller [`new`](Self::new) returns, built in place in `slot` (on the caller's
    /// stack or in a `static`) without a temporary copy: the big parts are written where they
    /// stay. On an error `slot` is `None`.
    pub fn new_in<'s>(
        slot: &'s mut Option<Self>,
        config: &ProsodyConfig,
        gmm: &[GmmComponent],
        crf: CrfWeights<'a>,
        tables: &'a T,
        lib: &'a L,
    ) -> Result<&'s mut Self, ControllerError> {
        Self::new_arith_in(slot, config, gmm, crf, tables, lib)
    }
}
