//! Logging through the simulation environment's printf-style callback.

use fmi_sys::fmi2::{
    fmi2CallbackLogger, fmi2ComponentEnvironment, fmi2Status, fmi2Status_fmi2Error,
    fmi2Status_fmi2Fatal, fmi2Status_fmi2Warning,
};
use std::ffi::CString;

use super::variables::{LogCategory, LOG_CATEGORIES};

/// How serious a message is; maps to the status passed to the callback.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Level {
    /// Progress and diagnostics (status fmi2OK); shown only when debug logging is on for its
    /// category.
    Info,
    /// A result the master should know about (fmi2Warning); always shown.
    Warning,
    /// A refused call or a failed step (fmi2Error); always shown.
    Error,
    /// The instance is unusable (fmi2Fatal); always shown.
    Fatal,
}

/// The environment's logger and which categories it asked for.
pub struct Logger {
    callback: fmi2CallbackLogger,
    environment: fmi2ComponentEnvironment,
    instance_name: CString,
    enabled: Vec<bool>,
    debug_logging: bool,
}

impl Logger {
    /// A logger calling `callback` (none: messages are dropped) with `environment` and the
    /// instance's name; `debug_logging` is `loggingOn` of fmi2Instantiate, with every category
    /// enabled.
    pub fn new(
        callback: fmi2CallbackLogger,
        environment: fmi2ComponentEnvironment,
        instance_name: &str,
        debug_logging: bool,
    ) -> Logger {
        Logger {
            callback,
            environment,
            instance_name: sanitized(instance_name),
            enabled: vec![true; LOG_CATEGORIES.len()],
            debug_logging,
        }
    }

    /// `fmi2SetDebugLogging`: with no categories, all are switched; unknown names are an error.
    pub fn set_debug_logging(&mut self, on: bool, categories: &[String]) -> Result<(), String> {
        if categories.is_empty() {
            self.debug_logging = on;
            self.enabled.iter_mut().for_each(|e| *e = true);
            return Ok(());
        }
        let mut indices = Vec::with_capacity(categories.len());
        for c in categories {
            match LOG_CATEGORIES.iter().position(|k| k == c) {
                Some(i) => indices.push(i),
                None => {
                    return Err(format!(
                        "unknown log category \"{c}\"; known: {}",
                        LOG_CATEGORIES.join(", ")
                    ))
                }
            }
        }
        if on {
            self.debug_logging = true;
            self.enabled.iter_mut().for_each(|e| *e = false);
        }
        for i in indices {
            self.enabled[i] = on;
        }
        Ok(())
    }

    fn category_enabled(&self, category: LogCategory) -> bool {
        self.enabled[category as usize]
    }

    /// Whether a message of `level` in `category` would reach the environment (callers skip
    /// formatting a per-step message nobody reads).
    pub fn wants(&self, level: Level, category: LogCategory) -> bool {
        let always = matches!(level, Level::Error | Level::Fatal | Level::Warning);
        always || (self.debug_logging && self.category_enabled(category) && self.callback.is_some())
    }

    /// Errors and warnings always reach the environment; other categories only when debug
    /// logging is on for them.
    pub fn log(&self, level: Level, category: LogCategory, message: &str) {
        if !self.wants(level, category) {
            return;
        }
        let Some(callback) = self.callback else {
            return;
        };
        let status: fmi2Status = match level {
            Level::Info => 0,
            Level::Warning => fmi2Status_fmi2Warning,
            Level::Error => fmi2Status_fmi2Error,
            Level::Fatal => fmi2Status_fmi2Fatal,
        };
        let category = sanitized(category.name());
        let message = sanitized(message);
        // SAFETY: the callback was supplied by the environment in fmi2Instantiate and stays valid
        // for the instance's lifetime (FMI 2.0 §2.1.5). The format is the literal "%s" and the
        // single vararg is a NUL-terminated string that outlives the call, so the printf-style
        // callee reads exactly one valid C string.
        unsafe {
            callback(
                self.environment,
                self.instance_name.as_ptr(),
                status,
                category.as_ptr(),
                c"%s".as_ptr(),
                message.as_ptr(),
            );
        }
    }
}

/// A C string without interior NUL bytes (they would truncate the message).
fn sanitized(text: &str) -> CString {
    CString::new(text.replace('\0', "\u{2400}")).unwrap_or_default()
}
