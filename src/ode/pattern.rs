//! The structure of a problem's Jacobian `df/dy`, which the problem may declare
//! ([`super::OdeProblem::jacobian_pattern`]) so that finite differences need fewer evaluations.

use super::error::BdfError;

/// Structure of `df/dy` in compressed-column form: rows of column `j` are
/// `row_idx[col_ptr[j]..col_ptr[j + 1]]`.
#[derive(Debug, Clone, PartialEq)]
pub struct JacobianPattern {
    n: usize,
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
}

impl JacobianPattern {
    /// Builds the pattern from the list of (possibly) non-zero rows of each column.
    pub fn from_columns(n: usize, columns: &[Vec<usize>]) -> Result<Self, BdfError> {
        if columns.len() != n {
            return Err(BdfError::InvalidInput {
                field: "jacobian_pattern",
                message: format!("has {} columns, the problem has {n} states", columns.len()),
            });
        }
        let mut col_ptr = Vec::with_capacity(n + 1);
        let mut row_idx = Vec::new();
        col_ptr.push(0);
        for (j, rows) in columns.iter().enumerate() {
            if let Some(&bad) = rows.iter().find(|&&i| i >= n) {
                return Err(BdfError::InvalidInput {
                    field: "jacobian_pattern",
                    message: format!("column {j} names row {bad}, the problem has {n} states"),
                });
            }
            let mut sorted = rows.clone();
            sorted.sort_unstable();
            sorted.dedup();
            row_idx.extend_from_slice(&sorted);
            col_ptr.push(row_idx.len());
        }
        Ok(Self {
            n,
            col_ptr,
            row_idx,
        })
    }

    /// Dimension of the (square) Jacobian.
    pub fn dim(&self) -> usize {
        self.n
    }

    /// Rows that column `j` may touch.
    pub fn rows(&self, j: usize) -> &[usize] {
        &self.row_idx[self.col_ptr[j]..self.col_ptr[j + 1]]
    }

    /// Greedy colouring: columns in one group share no row, so one RHS evaluation differentiates
    /// all of them (Curtis–Powell–Reid).
    pub fn column_groups(&self) -> Vec<Vec<usize>> {
        let mut groups: Vec<Vec<usize>> = Vec::new();
        let mut row_owner: Vec<Vec<bool>> = Vec::new();
        for j in 0..self.n {
            let rows = self.rows(j);
            let slot = row_owner
                .iter()
                .position(|used| rows.iter().all(|&i| !used[i]));
            let g = match slot {
                Some(g) => g,
                None => {
                    groups.push(Vec::new());
                    row_owner.push(vec![false; self.n]);
                    groups.len() - 1
                }
            };
            groups[g].push(j);
            for &i in rows {
                row_owner[g][i] = true;
            }
        }
        groups
    }
}
