//! The C API's integration tests: one binary, a module per subject. The error tests use the
//! renderer's GL fault injection (feature `testing`).

use splatgl_testkit as common;

#[cfg(feature = "testing")]
mod capi_errors;
mod capi_header;
mod capi_hosts;
