//! Validation-layer and driver messages, counted by severity so tests can assert zero.
//!
//! The messenger callback runs on driver threads and inside Vulkan calls: it never panics,
//! never blocks for long, and keeps at most [`KEPT_MESSAGES`] message texts.

use ash::vk;
use std::ffi::{CStr, c_void};
use std::sync::Mutex;
use std::sync::atomic::{AtomicU64, Ordering};

/// How many message texts are kept for reports; counting never stops.
pub const KEPT_MESSAGES: usize = 64;

/// Whether to load the Khronos validation layer.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Validation {
    /// No layer.
    #[default]
    Off,
    /// Use the layer (with synchronization validation) when it is installed.
    IfAvailable,
    /// Use the layer; fail if it is not installed.
    Required,
}

impl Validation {
    /// `SHINE_VALIDATION=1` → `Required`, `SHINE_VALIDATION=auto` → `IfAvailable`, else `Off`.
    pub fn from_env() -> Self {
        match std::env::var("SHINE_VALIDATION").as_deref() {
            Ok("1") | Ok("true") | Ok("on") => Self::Required,
            Ok("auto") => Self::IfAvailable,
            _ => Self::Off,
        }
    }
}

/// Counts of messages received, by severity.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct MessageCounts {
    /// Errors.
    pub errors: u64,
    /// Warnings.
    pub warnings: u64,
    /// Informational messages (not counted as problems).
    pub infos: u64,
}

impl MessageCounts {
    /// Errors plus warnings: what a clean run must keep at zero.
    pub fn problems(&self) -> u64 {
        self.errors + self.warnings
    }
}

/// Shared state behind the debug messenger.
#[derive(Default)]
pub(crate) struct MessageLog {
    errors: AtomicU64,
    warnings: AtomicU64,
    infos: AtomicU64,
    texts: Mutex<Vec<String>>,
}

impl MessageLog {
    pub(crate) fn counts(&self) -> MessageCounts {
        MessageCounts {
            errors: self.errors.load(Ordering::Relaxed),
            warnings: self.warnings.load(Ordering::Relaxed),
            infos: self.infos.load(Ordering::Relaxed),
        }
    }

    pub(crate) fn messages(&self) -> Vec<String> {
        match self.texts.lock() {
            Ok(texts) => texts.clone(),
            Err(poisoned) => poisoned.into_inner().clone(),
        }
    }

    fn record(&self, severity: vk::DebugUtilsMessageSeverityFlagsEXT, text: String) {
        let counter = if severity.contains(vk::DebugUtilsMessageSeverityFlagsEXT::ERROR) {
            &self.errors
        } else if severity.contains(vk::DebugUtilsMessageSeverityFlagsEXT::WARNING) {
            &self.warnings
        } else {
            &self.infos
        };
        counter.fetch_add(1, Ordering::Relaxed);
        let problem = severity.intersects(
            vk::DebugUtilsMessageSeverityFlagsEXT::ERROR
                | vk::DebugUtilsMessageSeverityFlagsEXT::WARNING,
        );
        if problem
            && let Ok(mut texts) = self.texts.lock()
            && texts.len() < KEPT_MESSAGES
        {
            texts.push(text);
        }
    }
}

/// Severities the messenger listens to.
pub(crate) fn severities() -> vk::DebugUtilsMessageSeverityFlagsEXT {
    vk::DebugUtilsMessageSeverityFlagsEXT::ERROR
        | vk::DebugUtilsMessageSeverityFlagsEXT::WARNING
        | vk::DebugUtilsMessageSeverityFlagsEXT::INFO
}

/// Message types the messenger listens to.
pub(crate) fn message_types() -> vk::DebugUtilsMessageTypeFlagsEXT {
    vk::DebugUtilsMessageTypeFlagsEXT::GENERAL
        | vk::DebugUtilsMessageTypeFlagsEXT::VALIDATION
        | vk::DebugUtilsMessageTypeFlagsEXT::PERFORMANCE
}

/// The debug-utils callback. `user_data` points at a live [`MessageLog`].
pub(crate) unsafe extern "system" fn callback(
    severity: vk::DebugUtilsMessageSeverityFlagsEXT,
    kind: vk::DebugUtilsMessageTypeFlagsEXT,
    data: *const vk::DebugUtilsMessengerCallbackDataEXT<'_>,
    user_data: *mut c_void,
) -> vk::Bool32 {
    // Unwinding out of an extern "system" fn aborts: contain anything unexpected.
    let _ = std::panic::catch_unwind(|| {
        if user_data.is_null() {
            return;
        }
        // SAFETY: user_data is the MessageLog owned by the device, alive while the messenger is.
        let log = unsafe { &*(user_data as *const MessageLog) };
        let problem = severity.intersects(
            vk::DebugUtilsMessageSeverityFlagsEXT::ERROR
                | vk::DebugUtilsMessageSeverityFlagsEXT::WARNING,
        );
        if !problem {
            log.record(severity, String::new());
            return;
        }
        let text = if data.is_null() {
            String::from("(no message data)")
        } else {
            // SAFETY: the loader passes a valid callback-data struct for this call.
            let data = unsafe { &*data };
            if data.p_message.is_null() {
                String::from("(empty message)")
            } else {
                // SAFETY: p_message is a NUL-terminated string valid for this call.
                unsafe { CStr::from_ptr(data.p_message) }
                    .to_string_lossy()
                    .into_owned()
            }
        };
        eprintln!("[vulkan {severity:?} {kind:?}] {text}");
        log.record(severity, text);
    });
    vk::FALSE
}
