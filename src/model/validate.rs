//! Checks shared by every configuration section: each failure names the field by its dotted path
//! and the offending value, so a user can find it in their JSON.

/// A configuration value that is out of its physical range.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("invalid configuration: {field}: {message}")]
pub struct ConfigError {
    /// Dotted path of the offending field, e.g. `mounts[2].curves[1].knots[0].stiffness`.
    pub field: String,
    /// What is wrong with its value.
    pub message: String,
}

pub(crate) fn err(field: impl Into<String>, message: impl Into<String>) -> ConfigError {
    ConfigError {
        field: field.into(),
        message: message.into(),
    }
}

pub(crate) fn positive(field: &str, v: f64) -> Result<(), ConfigError> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(err(
            field,
            format!("{field} = {v} must be a positive finite number"),
        ))
    }
}

pub(crate) fn non_negative(field: &str, v: f64) -> Result<(), ConfigError> {
    if v.is_finite() && v >= 0.0 {
        Ok(())
    } else {
        Err(err(
            field,
            format!("{field} = {v} must be a non-negative finite number"),
        ))
    }
}

pub(crate) fn finite(field: &str, v: &[f64]) -> Result<(), ConfigError> {
    match v.iter().find(|x| !x.is_finite()) {
        Some(x) => Err(err(field, format!("{field} contains {x}, must be finite"))),
        None => Ok(()),
    }
}

/// A unit vector (within 1e-6), reported with its norm otherwise.
pub(crate) fn unit_vector(field: &str, v: &[f64; 3]) -> Result<(), ConfigError> {
    finite(field, v)?;
    let norm = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    if (norm - 1.0).abs() > 1e-6 {
        return Err(err(
            field,
            format!("{field} = {v:?} must be a unit vector (norm {norm})"),
        ));
    }
    Ok(())
}

/// A physically possible inertia tensor: symmetric, positive definite, principal moments obeying
/// the triangle inequality.
pub(crate) fn inertia_tensor(field: &str, j: &[[f64; 3]; 3]) -> Result<(), ConfigError> {
    finite(field, &j.concat())?;
    let m = nalgebra::Matrix3::from_fn(|r, c| j[r][c]);
    if (m - m.transpose()).abs().max() > 1e-9 * m.abs().max().max(1e-30) {
        return Err(err(field, format!("{field} = {j:?} must be symmetric")));
    }
    let eig = m.symmetric_eigen().eigenvalues;
    let (a, b, c) = (eig[0], eig[1], eig[2]);
    if a.min(b).min(c) <= 0.0 {
        return Err(err(
            field,
            format!("{field} = {j:?} must be positive definite (eigenvalues {a}, {b}, {c})"),
        ));
    }
    // Triangle inequality of principal moments: otherwise no mass distribution has this tensor.
    let tol = 1e-9 * (a + b + c);
    if a + b < c - tol || a + c < b - tol || b + c < a - tol {
        return Err(err(
            field,
            format!("{field} = {j:?} violates the triangle inequality of principal moments"),
        ));
    }
    Ok(())
}
