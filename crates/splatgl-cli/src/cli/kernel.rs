//! `--antialiased auto|on|off` of `render` and `view`: the kernel a file is drawn with.

use splatgl::load::AntialiasMode;

/// The kernel (`docs/rendering-profile.md` § Antialiased kernel).
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum AntialiasArg {
    /// Antialiased when the file says it was trained so (SPZ header flag 0x1), else plain.
    Auto,
    /// Opacity × √(det Σ' / det(Σ' + 0.3 I)): for scenes trained with Mip-Splatting's 2D
    /// filter or gsplat's `antialiased` mode.
    On,
    /// The plain 3DGS kernel.
    Off,
}

impl AntialiasArg {
    /// The library's mode.
    pub fn mode(self) -> AntialiasMode {
        match self {
            AntialiasArg::Auto => AntialiasMode::Auto,
            AntialiasArg::On => AntialiasMode::On,
            AntialiasArg::Off => AntialiasMode::Off,
        }
    }
}
