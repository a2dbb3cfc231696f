//! [`ShowPlayer`]: a show's commands carried out by a bare [`Player`] on the sample clock,
//! giving the poses the controller gave.

use super::error::ShowError;
use super::parse::{Commands, Show};
use crate::blob::Blob;
use crate::follow::rest_segments;
use crate::player::{
    library_speed_cap, within_limits, LibraryFrames, Player, PlayerCommand, MAX_CHANNELS,
};

/// One tick of a show: its pose and what it showed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShowTick<'p> {
    /// Tick number from 0.
    pub tick: u64,
    /// Channel values (degrees), within the rig's limits.
    pub pose: &'p [f32],
    /// Library segment played (the target of a blend during one).
    pub segment: usize,
    /// Frame of that segment played.
    pub frame: usize,
}

/// Plays a validated [`Show`] over a library: samples counted in, a pose out at every tick
/// due, exactly the controller's (see the module docs). Fixed memory (a [`Player`] and one
/// pose), no allocation, no panics.
pub struct ShowPlayer<'a, L: LibraryFrames + ?Sized> {
    lib: &'a L,
    commands: Commands<'a>,
    /// The next command, read ahead.
    next: Option<(u64, PlayerCommand)>,
    player: Player,
    pose: [f32; MAX_CHANNELS],
    rate: u64,
    fps_milli: u64,
    samples: u64,
    tick: u64,
    ticks: u64,
}

impl<'a> ShowPlayer<'a, Blob<'a>> {
    /// The player of `show` over `blob`, set up as the controller sets up its player (the
    /// blob's blend time, the library's speed cap and its rest segments), after
    /// [`Show::check_against`] `blob`.
    pub fn from_blob(show: &Show<'a>, blob: &'a Blob<'a>) -> Result<Self, ShowError> {
        show.check_against(blob)?;
        let fps_milli = show.header().fps_milli as u64;
        // As the controller's `ms_ticks`.
        let blend = (blob.blend_ms() as u64 * fps_milli).div_ceil(1_000_000);
        let mut me = Self::new(
            show,
            blob,
            blend.min(u32::MAX as u64) as u32,
            library_speed_cap(blob),
        )?;
        let segments = LibraryFrames::segment_count(blob);
        me.player
            .set_rest_segments(rest_segments(blob, segments, &blob.follow()));
        Ok(me)
    }
}

impl<'a, L: LibraryFrames + ?Sized> ShowPlayer<'a, L> {
    /// The player of `show` over `lib`, whose cuts blend over `blend_ticks` with the speed cap
    /// `speed_cap` (degrees per tick; what the controller's player had: a controller from a
    /// blob sets both from the blob, and its rest segments, [`from_blob`](ShowPlayer::from_blob);
    /// here none), after [`Show::check_library`].
    pub fn new(
        show: &Show<'a>,
        lib: &'a L,
        blend_ticks: u32,
        speed_cap: f32,
    ) -> Result<Self, ShowError> {
        show.check_library(lib)?;
        let mut player = Player::new();
        player.set_blend_ticks(blend_ticks);
        player.set_speed_cap(speed_cap);
        let mut commands = show.commands();
        let next = commands.next();
        Ok(Self {
            lib,
            commands,
            next,
            player,
            pose: [0.0; MAX_CHANNELS],
            rate: show.header().sample_rate_hz as u64,
            fps_milli: show.header().fps_milli as u64,
            samples: 0,
            tick: 0,
            ticks: show.ticks(),
        })
    }

    /// Samples needed before tick `k` is due: `ceil(k * rate / fps)`, as the controller.
    fn due(&self, k: u64) -> u64 {
        k.saturating_mul(self.rate)
            .saturating_mul(1000)
            .div_ceil(self.fps_milli.max(1))
    }

    /// Counts `samples` more samples of the sample clock and plays every tick now due
    /// (tick 0 is due at once), reporting each through `sink`. After the show's last tick
    /// nothing more is reported and [`pose`](Self::pose) holds the last pose.
    pub fn push(&mut self, samples: usize, sink: &mut impl FnMut(ShowTick<'_>)) {
        self.samples = self.samples.saturating_add(samples as u64);
        while self.tick < self.ticks && self.samples >= self.due(self.tick) {
            self.step(sink);
        }
    }

    /// Plays one tick: the commands stamped for it first, then the frame, clamped to the
    /// rig's limits as the controller clamps it.
    fn step(&mut self, sink: &mut impl FnMut(ShowTick<'_>)) {
        let mut advance = true;
        while let Some((t, c)) = self.next {
            if t > self.tick {
                break;
            }
            match c {
                PlayerCommand::Hold => advance = false,
                c => self.player.apply(self.lib, c),
            }
            self.next = self.commands.next();
        }
        let segment = self.player.segment();
        let frame = self
            .player
            .tick_advancing(self.lib, &mut self.pose, advance);
        let channels = within_limits(self.lib, &mut self.pose);
        let tick = self.tick;
        self.tick += 1;
        sink(ShowTick {
            tick,
            pose: &self.pose[..channels],
            segment,
            frame,
        });
    }

    /// The last pose played (all zero before the first tick).
    pub fn pose(&self) -> &[f32] {
        &self.pose[..self.lib.channels().min(MAX_CHANNELS)]
    }

    /// Ticks played so far.
    pub fn ticks_played(&self) -> u64 {
        self.tick
    }

    /// Whether every tick of the show has played.
    pub fn finished(&self) -> bool {
        self.tick >= self.ticks
    }

    /// Samples counted so far.
    pub fn samples(&self) -> u64 {
        self.samples
    }
}
