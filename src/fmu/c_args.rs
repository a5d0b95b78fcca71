//! C arguments as Rust values, for both ABIs (FMI 2.0 and 3.0 pass arrays, out-parameters and
//! strings alike): arrays become slices, an out-parameter a reference, a C string a `String`;
//! null pointers where a value is needed are refused with a message naming the argument.

use std::ffi::{c_char, CStr};

/// A slice from the C array `name` of `n` elements; a null pointer with `n > 0` is refused.
///
/// # Safety
/// `ptr` must be null or point to `n` initialised elements that stay valid and unaliased for `'a`.
pub unsafe fn array<'a, T>(ptr: *const T, n: usize, name: &str) -> Result<&'a [T], String> {
    if n == 0 {
        Ok(&[])
    } else if ptr.is_null() {
        Err(format!("argument {name} is NULL"))
    } else {
        // SAFETY: guaranteed by the caller's contract above.
        Ok(unsafe { std::slice::from_raw_parts(ptr, n) })
    }
}

/// As [`array()`], for writing.
///
/// # Safety
/// As [`array()`], and the elements must be writable.
pub unsafe fn array_mut<'a, T>(ptr: *mut T, n: usize, name: &str) -> Result<&'a mut [T], String> {
    if n == 0 {
        Ok(&mut [])
    } else if ptr.is_null() {
        Err(format!("argument {name} is NULL"))
    } else {
        // SAFETY: guaranteed by the caller's contract above.
        Ok(unsafe { std::slice::from_raw_parts_mut(ptr, n) })
    }
}

/// The single writable element behind `ptr`; a null pointer is refused.
///
/// # Safety
/// `ptr` must be null or point to a writable `T` valid for `'a`.
pub unsafe fn place<'a, T>(ptr: *mut T, name: &str) -> Result<&'a mut T, String> {
    // SAFETY: guaranteed by the caller's contract above.
    unsafe { ptr.as_mut() }.ok_or_else(|| format!("argument {name} is NULL"))
}

/// A Rust string from a C string; `None` for null or invalid UTF-8.
///
/// # Safety
/// `ptr` is null or a NUL-terminated string valid for the call.
pub unsafe fn text(ptr: *const c_char) -> Option<String> {
    if ptr.is_null() {
        return None;
    }
    // SAFETY: non-null and NUL-terminated by the caller's contract.
    unsafe { CStr::from_ptr(ptr) }
        .to_str()
        .ok()
        .map(str::to_owned)
}

/// Strings from the C array `name` of `n` C strings; null or non-UTF-8 entries are refused.
///
/// # Safety
/// As [`array()`], each entry null or a NUL-terminated string valid for the call.
pub unsafe fn texts(
    ptr: *const *const c_char,
    n: usize,
    name: &str,
) -> Result<Vec<String>, String> {
    // SAFETY: the caller's contract.
    let raw = unsafe { array(ptr, n, name) }?;
    raw.iter()
        // SAFETY: each entry is null or NUL-terminated, by the caller's contract.
        .map(|p| unsafe { text(*p) })
        .collect::<Option<Vec<_>>>()
        .ok_or_else(|| format!("an entry of {name} is NULL or not UTF-8"))
}

/// A string value an FMU variable is set to: a null or non-UTF-8 C string is refused.
///
/// # Safety
/// `ptr` is null or a NUL-terminated string valid for the call.
pub unsafe fn string_value(ptr: *const c_char) -> Result<String, String> {
    // SAFETY: the caller's contract.
    unsafe { text(ptr) }.ok_or_else(|| "a value is NULL or not UTF-8".to_owned())
}
