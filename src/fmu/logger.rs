//! Logging through the simulation environment's callback: FMI 2.0's printf-style one, or FMI
//! 3.0's, which takes the message as it is.

use fmi_sys::fmi2::{
    fmi2CallbackLogger, fmi2ComponentEnvironment, fmi2Status, fmi2Status_fmi2Error,
    fmi2Status_fmi2Fatal, fmi2Status_fmi2Warning,
};
use fmi_sys::fmi3::fmi3LogMessageCallback;
use std::ffi::CString;

use crate::variables::{LogCategory, LOG_CATEGORIES};

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

/// The environment's callback, of the standard the instance was created through.
#[derive(Clone, Copy)]
enum Callback {
    Fmi2(fmi2CallbackLogger),
    Fmi3(fmi3LogMessageCallback),
}

impl Callback {
    fn is_some(self) -> bool {
        match self {
            Callback::Fmi2(c) => c.is_some(),
            Callback::Fmi3(c) => c.is_some(),
        }
    }
}

/// The environment's logger and which categories it asked for.
#[derive(Clone)]
pub struct Logger {
    callback: Callback,
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
            callback: Callback::Fmi2(callback),
            environment,
            instance_name: sanitized(instance_name),
            enabled: vec![true; LOG_CATEGORIES.len()],
            debug_logging,
        }
    }

    /// A logger for an FMI 3.0 instance: as [`Logger::new`], with the 3.0 callback, which gets
    /// the instance environment and no instance name.
    pub fn new_fmi3(
        callback: fmi3LogMessageCallback,
        environment: *mut std::ffi::c_void,
        instance_name: &str,
        debug_logging: bool,
    ) -> Logger {
        Logger {
            callback: Callback::Fmi3(callback),
            ..Logger::new(None, environment, instance_name, debug_logging)
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
        let status: fmi2Status = match level {
            Level::Info => 0,
            Level::Warning => fmi2Status_fmi2Warning,
            Level::Error => fmi2Status_fmi2Error,
            Level::Fatal => fmi2Status_fmi2Fatal,
        };
        let category = sanitized(category.name());
        let message = sanitized(message);
        match self.callback {
            // SAFETY: the callback was supplied by the environment in fmi2Instantiate and stays
            // valid for the instance's lifetime (FMI 2.0 §2.1.5). The format is the literal "%s"
            // and the single vararg is a NUL-terminated string that outlives the call, so the
            // printf-style callee reads exactly one valid C string.
            Callback::Fmi2(Some(callback)) => unsafe {
                callback(
                    self.environment,
                    self.instance_name.as_ptr(),
                    status,
                    category.as_ptr(),
                    c"%s".as_ptr(),
                    message.as_ptr(),
                );
            },
            // SAFETY: supplied by the environment in fmi3InstantiateCoSimulation, valid for the
            // instance's lifetime (FMI 3.0 §2.3.1); both strings are NUL-terminated and outlive
            // the call. fmi3Status and fmi2Status number OK..Fatal alike.
            Callback::Fmi3(Some(callback)) => unsafe {
                callback(
                    self.environment,
                    status,
                    category.as_ptr(),
                    message.as_ptr(),
                );
            },
            Callback::Fmi2(None) | Callback::Fmi3(None) => {}
        }
    }
}

/// A C string without interior NUL bytes (they would truncate the message).
fn sanitized(text: &str) -> CString {
    CString::new(text.replace('\0', "\u{2400}")).unwrap_or_default()
}
