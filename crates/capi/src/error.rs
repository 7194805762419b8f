//! Result codes and the thread's last error message: every entry point runs through [`call`],
//! which turns errors and panics into a code and keeps the message for [`shine_last_error`].

use std::cell::RefCell;
use std::ffi::{CString, c_char};

/// What a call returned, `VkResult`-style: 0 is success, errors are negative.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ShineResult {
    /// The call did what it says.
    Success = 0,
    /// A handle argument was null.
    ErrorNullHandle = -1,
    /// A handle was destroyed, never made, or of another kind.
    ErrorStaleHandle = -2,
    /// An argument was out of range, inconsistent or null where it may not be.
    ErrorInvalidArgument = -3,
    /// A descriptor's `version` is not the one this library was built for.
    ErrorVersionMismatch = -4,
    /// The host's device lacks a feature, extension or queue shine needs.
    ErrorMissingFeatures = -5,
    /// A Vulkan call failed (out of memory, device lost …).
    ErrorVulkan = -6,
    /// A scene file could not be read or understood.
    ErrorScene = -7,
    /// A bug in shine (a panic was caught at the boundary); the handle may be unusable.
    ErrorInternal = -8,
}

/// A failed call: its code and what to tell the host.
#[derive(Debug)]
pub(crate) struct Failure {
    pub code: ShineResult,
    pub message: String,
}

impl Failure {
    /// A failure with `code` and `message`.
    pub(crate) fn new(code: ShineResult, message: impl Into<String>) -> Self {
        Self {
            code,
            message: message.into(),
        }
    }

    /// An invalid-argument failure.
    pub(crate) fn invalid(message: impl Into<String>) -> Self {
        Self::new(ShineResult::ErrorInvalidArgument, message)
    }
}

impl From<shine::RenderError> for Failure {
    fn from(e: shine::RenderError) -> Self {
        use shine::RenderError as R;
        use shine::gpu::Error as G;
        let code = match &e {
            R::Gpu(G::MissingFeatures { .. }) => ShineResult::ErrorMissingFeatures,
            R::Gpu(G::InvalidUsage(_)) | R::Invalid(_) | R::Settings(_) | R::NoScene => {
                ShineResult::ErrorInvalidArgument
            }
            R::Gpu(_) | R::Graph(_) => ShineResult::ErrorVulkan,
            _ => ShineResult::ErrorInvalidArgument,
        };
        Self::new(code, e.to_string())
    }
}

impl From<shine::gpu::Error> for Failure {
    fn from(e: shine::gpu::Error) -> Self {
        shine::RenderError::from(e).into()
    }
}

thread_local! {
    /// The message of this thread's last failed call.
    static LAST_ERROR: RefCell<CString> = RefCell::new(CString::default());
}

/// Runs an entry point: its error, or a panic, becomes a code and this thread's last message.
pub(crate) fn call(f: impl FnOnce() -> Result<(), Failure>) -> ShineResult {
    let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(f)).unwrap_or_else(|p| {
        let what = p
            .downcast_ref::<&str>()
            .map(|s| (*s).to_owned())
            .or_else(|| p.downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "unknown panic".into());
        Err(Failure::new(
            ShineResult::ErrorInternal,
            format!("internal error: {what}"),
        ))
    });
    let (code, message) = match outcome {
        Ok(()) => (ShineResult::Success, String::new()),
        Err(f) => (f.code, f.message),
    };
    let message = CString::new(message.replace('\0', " ")).unwrap_or_default();
    LAST_ERROR.with(|m| *m.borrow_mut() = message);
    code
}

/// The message of the calling thread's last call: empty after a success, what went wrong
/// after an error. Valid until the thread's next shine call; never null.
#[unsafe(no_mangle)]
pub extern "C" fn shine_last_error() -> *const c_char {
    LAST_ERROR.with(|m| m.borrow().as_ptr())
}
