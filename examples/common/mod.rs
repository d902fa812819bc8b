//! What the windowed examples share: `--screenshot FILE --frames N`, the
//! scenes of `domino_show`, `pile` and the frame benchmark, and their drawing.

use std::path::PathBuf;

use bevy::prelude::*;
use bevy::render::view::screenshot::{save_to_disk, Screenshot, ScreenshotCaptured};

/// Frames to wait for the screenshot after asking for it before giving up.
const SCREENSHOT_PATIENCE: u32 = 120;

/// At `frame == frames` asks for a screenshot of the window saved to `file`,
/// and exits with success once it is written; exits with an error if it
/// has not come `SCREENSHOT_PATIENCE` frames later.
pub fn screenshot_then_exit(
    commands: &mut Commands,
    exit: &mut MessageWriter<AppExit>,
    file: PathBuf,
    frame: u32,
    frames: u32,
) {
    if frame == frames {
        commands
            .spawn(Screenshot::primary_window())
            .observe(save_to_disk(file))
            .observe(
                |_: On<ScreenshotCaptured>, mut exit: MessageWriter<AppExit>| {
                    exit.write(AppExit::Success);
                },
            );
    } else if frame > frames + SCREENSHOT_PATIENCE {
        error!("no screenshot {SCREENSHOT_PATIENCE} frames after asking for it");
        exit.write(AppExit::from_code(1));
    }
}

pub mod scenes;
pub mod show;
pub mod view;
