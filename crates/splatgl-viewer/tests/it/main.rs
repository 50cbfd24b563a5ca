//! The viewer crate's integration tests: one binary, a module per subject.

use splatgl_testkit as common;

mod viewer_panel_gl;
