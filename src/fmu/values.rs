//! The FMU's variable values: one store per variable type, generic over the type, addressed
//! through the generated variable table. This is the one place where a value is checked against
//! its declaration ([`VarType::admissible`]); the ABIs resolve value references to positions
//! ([`Slot`]).

use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};

use crate::variables::{Causality, Variable, BOOLEANS, INTEGERS, REALS, STRINGS};

/// The values of one variable type, indexed by the variable's position in its table.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Store<T> {
    values: Vec<T>,
    /// Which variables the master set itself: such a parameter wins over the vehicle
    /// configuration's value (and `solver.relTol` over the experiment's tolerance).
    set_by_master: Vec<bool>,
}

impl<T: VarType> Store<T> {
    /// Every variable at its start value, none set by the master.
    pub fn start() -> Self {
        Store {
            values: T::table().iter().map(T::start).collect(),
            set_by_master: vec![false; T::table().len()],
        }
    }

    /// The value of the variable at `index` (a constant of [`crate::variables::real`], …).
    pub fn get(&self, index: u32) -> &T {
        &self.values[index as usize]
    }

    /// Writes a value the FMU computed (an output, the effective value of a parameter).
    pub fn put(&mut self, index: u32, value: T) {
        self.values[index as usize] = value;
    }

    /// Whether the master set the variable at `index`.
    pub fn set_by_master(&self, index: u32) -> bool {
        self.set_by_master[index as usize]
    }

    /// All values, by index.
    pub fn as_slice(&self) -> &[T] {
        &self.values
    }

    /// The store after the master sets `values` at `indices`, if every one may be set now
    /// (`settable`) and is admissible; nothing changes here.
    pub fn with_set(
        &self,
        indices: &[usize],
        values: &[T],
        settable: impl Fn(&Variable<T::Start>) -> Result<(), String>,
    ) -> Result<Self, String> {
        let mut next = self.clone();
        for (&i, value) in indices.iter().zip(values) {
            let v = &T::table()[i];
            settable(v)?;
            T::admissible(v, value)?;
            next.values[i] = value.clone();
            next.set_by_master[i] = true;
        }
        Ok(next)
    }

    /// Whether the store fits the table (a deserialized state) and every value is admissible.
    pub fn check(&self) -> Result<(), String> {
        let n = T::table().len();
        if self.values.len() != n || self.set_by_master.len() != n {
            return Err(format!(
                "{} {} values, this FMU has {n}",
                self.values.len(),
                T::NAME
            ));
        }
        T::table()
            .iter()
            .zip(&self.values)
            .try_for_each(|(v, x)| T::admissible(v, x))
    }
}

/// A variable type of FMI 2.0 as the FMU stores it.
pub trait VarType: Clone + PartialEq + Serialize + DeserializeOwned + 'static {
    /// How the generated table declares the start value.
    type Start: 'static;
    /// `Real`, `Integer`, `Boolean` or `String`.
    const NAME: &'static str;
    /// Position of the type in [`crate::variables::VR_BASE`].
    const TYPE_INDEX: usize;
    /// The type's variables.
    fn table() -> &'static [Variable<Self::Start>];
    /// A variable's start value.
    fn start(v: &Variable<Self::Start>) -> Self;
    /// Whether `value` is admissible for `v`: finite, and within the declared range for inputs
    /// and parameters (outputs are computed, not checked).
    fn admissible(v: &Variable<Self::Start>, value: &Self) -> Result<(), String>;
}

/// A number as a message shows it: plain where that is short, in exponent form where plain
/// decimals would run to many digits (`1.39e-160`, not 160 digits).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Num(pub f64);

impl std::fmt::Display for Num {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let x = self.0;
        if x == 0.0 || !x.is_finite() || (1e-4..1e16).contains(&x.abs()) {
            write!(f, "{x}")
        } else {
            write!(f, "{x:e}")
        }
    }
}

/// A value outside `[min, max]` of an input or parameter, as a message.
fn outside_range<T: PartialOrd + Copy + Into<f64>>(
    v: &Variable<T>,
    value: T,
    lowest: T,
    highest: T,
) -> Result<(), String> {
    let ranged = matches!(v.causality, Causality::Input | Causality::Parameter);
    if ranged && (v.min.is_some_and(|m| value < m) || v.max.is_some_and(|m| value > m)) {
        return Err(format!(
            "{} = {} is outside [{}, {}]",
            v.name,
            Num(value.into()),
            Num(v.min.unwrap_or(lowest).into()),
            Num(v.max.unwrap_or(highest).into())
        ));
    }
    Ok(())
}

impl VarType for f64 {
    type Start = f64;
    const NAME: &'static str = "Real";
    const TYPE_INDEX: usize = 0;
    fn table() -> &'static [Variable<f64>] {
        REALS
    }
    fn start(v: &Variable<f64>) -> f64 {
        v.start
    }
    fn admissible(v: &Variable<f64>, value: &f64) -> Result<(), String> {
        if !value.is_finite() {
            return Err(format!("{} = {} is not finite", v.name, Num(*value)));
        }
        outside_range(v, *value, f64::NEG_INFINITY, f64::INFINITY)
    }
}

impl VarType for i32 {
    type Start = i32;
    const NAME: &'static str = "Integer";
    const TYPE_INDEX: usize = 1;
    fn table() -> &'static [Variable<i32>] {
        INTEGERS
    }
    fn start(v: &Variable<i32>) -> i32 {
        v.start
    }
    fn admissible(v: &Variable<i32>, value: &i32) -> Result<(), String> {
        outside_range(v, *value, i32::MIN, i32::MAX)
    }
}

impl VarType for bool {
    type Start = bool;
    const NAME: &'static str = "Boolean";
    const TYPE_INDEX: usize = 2;
    fn table() -> &'static [Variable<bool>] {
        BOOLEANS
    }
    fn start(v: &Variable<bool>) -> bool {
        v.start
    }
    fn admissible(_: &Variable<bool>, _: &bool) -> Result<(), String> {
        Ok(())
    }
}

impl VarType for String {
    type Start = &'static str;
    const NAME: &'static str = "String";
    const TYPE_INDEX: usize = 3;
    fn table() -> &'static [Variable<&'static str>] {
        STRINGS
    }
    fn start(v: &Variable<&'static str>) -> String {
        v.start.to_owned()
    }
    fn admissible(_: &Variable<&'static str>, _: &String) -> Result<(), String> {
        Ok(())
    }
}

/// Where one value of a get or set call goes, once the ABI has resolved the master's value
/// reference.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Slot {
    /// The variable of the table at this index among its type.
    Element(usize),
    /// The independent variable `time` (FMI 3.0 has it as a variable).
    Time,
}

impl Slot {
    /// The variable's index, unless this is `time`.
    pub fn element(&self) -> Option<usize> {
        match self {
            Slot::Element(i) => Some(*i),
            Slot::Time => None,
        }
    }
}

/// All variable values.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Values {
    /// The Real variables, indexed like [`REALS`] (in the units of the model description).
    pub reals: Store<f64>,
    /// The Integer variables, indexed like [`INTEGERS`].
    pub integers: Store<i32>,
    /// The Boolean variables, indexed like [`BOOLEANS`].
    pub booleans: Store<bool>,
    /// The String variables, indexed like [`STRINGS`].
    pub strings: Store<String>,
}

impl Values {
    /// Every variable at its start value.
    pub fn start() -> Values {
        Values {
            reals: Store::start(),
            integers: Store::start(),
            booleans: Store::start(),
            strings: Store::start(),
        }
    }

    /// The store of type `T`.
    pub fn of<T: Typed>(&self) -> &Store<T> {
        T::store(self)
    }

    /// The store of type `T`, to change.
    pub fn of_mut<T: Typed>(&mut self) -> &mut Store<T> {
        T::store_mut(self)
    }

    /// Whether every store fits the table and every value is admissible (a deserialized state).
    pub fn check(&self) -> Result<(), String> {
        self.reals.check()?;
        self.integers.check()?;
        self.booleans.check()?;
        self.strings.check()
    }
}

/// Where [`Values`] keeps a type's store.
pub trait Typed: VarType {
    /// The store of this type in `values`.
    fn store(values: &Values) -> &Store<Self>;
    /// The store of this type in `values`, to change.
    fn store_mut(values: &mut Values) -> &mut Store<Self>;
}

macro_rules! typed {
    ($ty:ty, $field:ident) => {
        impl Typed for $ty {
            fn store(values: &Values) -> &Store<Self> {
                &values.$field
            }
            fn store_mut(values: &mut Values) -> &mut Store<Self> {
                &mut values.$field
            }
        }
    };
}
typed!(f64, reals);
typed!(i32, integers);
typed!(bool, booleans);
typed!(String, strings);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::variables::{boolean, real};

    /// Issue 28: numbers were logged as 160-digit decimals.
    #[test]
    fn numbers_in_messages_stay_short() {
        assert_eq!(Num(1.39e-160).to_string(), "1.39e-160");
        assert_eq!(Num(-2.5e300).to_string(), "-2.5e300");
        assert_eq!(Num(0.0).to_string(), "0");
        assert_eq!(Num(6000.0).to_string(), "6000");
        assert_eq!(Num(1e-5).to_string(), "1e-5");
        assert_eq!(Num(f64::NAN).to_string(), "NaN");
        let v = &REALS[real::RPM as usize];
        let m = f64::admissible(v, &-1.39e-160).unwrap_err();
        assert!(m.contains("-1.39e-160 is outside"), "{m}");
    }

    #[test]
    fn a_set_is_checked_whole_and_marks_what_the_master_set() {
        let start = Store::<f64>::start();
        let i = real::SOLVER_REL_TOL as usize;
        let rpm = real::RPM as usize;
        let any = |_: &Variable<f64>| Ok(());
        let next = start.with_set(&[i], &[1e-6], any).unwrap();
        assert_eq!(*next.get(real::SOLVER_REL_TOL), 1e-6);
        assert!(next.set_by_master(real::SOLVER_REL_TOL));
        assert!(!next.set_by_master(real::RPM));
        // One bad value refuses the whole set.
        assert!(start.with_set(&[rpm, i], &[1000.0, 7.0], any).is_err());
        assert!(start.with_set(&[rpm], &[f64::NAN], any).is_err());
        let b = Store::<bool>::start();
        let j = boolean::EFFECT_GAS_FORCES as usize;
        assert!(b.with_set(&[j], &[false], |_| Ok(())).is_ok());
        assert!(b
            .with_set(&[j], &[false], |_| Err("not now".into()))
            .is_err());
    }
}
