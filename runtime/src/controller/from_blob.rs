//! A controller over a validated blob: its tables, front-end settings, decision timing,
//! variety, labels' timeout, voice following, blend and speed cap, all from the blob.

use super::{Controller, ControllerError};
use crate::blob::Blob;

impl<'a> Controller<'a, Blob<'a>, Blob<'a>> {
    /// The controller over a validated blob's tables, with the blob's front-end settings and
    /// decision timing: the one way host tools and boards build a controller.
    ///
    /// The controller is about 15 KiB and is copied on the stack on its way out of here; a
    /// board with little RAM builds it in place with [`from_blob_in`](Self::from_blob_in).
    pub fn from_blob(blob: &'a Blob<'a>) -> Result<Self, ControllerError> {
        let mut slot = None;
        Self::from_blob_in(&mut slot, blob)?;
        slot.ok_or(ControllerError::Dimensions)
    }

    /// [`from_blob`](Self::from_blob), built in place in `slot` (on the caller's stack or in
    /// a `static`) without a temporary copy. On an error `slot` is `None`.
    pub fn from_blob_in<'s>(
        slot: &'s mut Option<Self>,
        blob: &'a Blob<'a>,
    ) -> Result<&'s mut Self, ControllerError> {
        let gmm = blob.gmm();
        let config = blob.prosody_config();
        let me = Self::new_in(
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
        let blend = me.ms_ticks(blob.blend_ms());
        me.player.set_blend_ticks(blend);
        me.player
            .set_speed_cap(crate::player::library_speed_cap(blob));
        Ok(me)
    }
}
