//! Fields given as data: a number, or an expression of the position (x, y) in m, compiled
//! once with its exact gradient (exmex's symbolic differentiation). The fluid's and the MPM's
//! `[initial]` tables use them.

use exmex::prelude::*;
use exmex::{literal_matcher_from_pattern, Differentiate, FloatOpsFactory, MatchLiteral};
use serde::{Deserialize, Serialize};

use crate::{Error, Result};

// Numbers as TOML writes them, with an exponent (1.5e-3, 2E+4).
literal_matcher_from_pattern!(Number, r"^([0-9]+(\.[0-9]*)?|\.[0-9]+)([eE][+-]?[0-9]+)?");

/// An expression of x and y with the float operators and numbers with exponents.
type Expr = FlatEx<f64, FloatOpsFactory<f64>, Number>;

/// One component of an initial field: a number or an expression of x and y (m).
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(untagged)]
pub enum FieldValue {
    /// The same value everywhere.
    Uniform(f64),
    /// An expression of x and y in m: numbers, `+ - * / ^`, parentheses, `PI`, `E` and the
    /// functions sin, cos, tan, asin, acos, atan, sinh, cosh, tanh, exp, ln, log, sqrt, cbrt,
    /// abs, signum, min, max, floor, ceil, round.
    Expression(String),
}

impl<'de> Deserialize<'de> for FieldValue {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        struct Visitor;
        impl serde::de::Visitor<'_> for Visitor {
            type Value = FieldValue;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a number or an expression of x and y in quotes, e.g. \"0.1*sin(x)\"")
            }
            fn visit_f64<E>(self, v: f64) -> std::result::Result<FieldValue, E> {
                Ok(FieldValue::Uniform(v))
            }
            fn visit_i64<E>(self, v: i64) -> std::result::Result<FieldValue, E> {
                Ok(FieldValue::Uniform(v as f64))
            }
            fn visit_u64<E>(self, v: u64) -> std::result::Result<FieldValue, E> {
                Ok(FieldValue::Uniform(v as f64))
            }
            fn visit_str<E>(self, v: &str) -> std::result::Result<FieldValue, E> {
                Ok(FieldValue::Expression(v.to_owned()))
            }
        }
        d.deserialize_any(Visitor)
    }
}

/// What the hand-written [`Deserialize`] above accepts: a number (an integer too) or a string.
impl schemars::JsonSchema for FieldValue {
    fn schema_name() -> std::borrow::Cow<'static, str> {
        "FieldValue".into()
    }

    fn json_schema(_: &mut schemars::SchemaGenerator) -> schemars::Schema {
        schemars::json_schema!({
            "description": "A number, or an expression of x and y (m) in quotes, e.g. \"0.1*sin(x)\".",
            "anyOf": [
                { "type": "number", "description": "The same value everywhere." },
                {
                    "type": "string",
                    "description": "An expression of x and y in m: numbers, `+ - * / ^`, \
                        parentheses, `PI`, `E` and the functions sin, cos, tan, asin, acos, \
                        atan, sinh, cosh, tanh, exp, ln, log, sqrt, cbrt, abs, signum, min, \
                        max, floor, ceil, round."
                }
            ]
        })
    }
}

/// One compiled component: its value and its gradient in x and y.
pub(crate) struct Scalar {
    /// The key it was read from.
    pub(crate) key: &'static str,
    /// Value, ∂/∂x, ∂/∂y (boxed: an exmex expression holds its nodes inline, kilobytes each).
    parts: Option<Box<[Expr; 3]>>,
    /// Where there is no expression: the value.
    uniform: f64,
}

impl Scalar {
    /// Compile `v`, read from `key`: an expression that does not parse or uses a variable
    /// other than x and y is refused naming the key.
    pub(crate) fn new(key: &'static str, v: &FieldValue) -> Result<Self> {
        let text = match v {
            FieldValue::Uniform(u) => {
                return Ok(Scalar {
                    key,
                    parts: None,
                    uniform: *u,
                })
            }
            FieldValue::Expression(text) => text,
        };
        let bad = |why: String| Error::config(key, why);
        // Parsed with both variables declared (`+0*x+0*y`), so every part takes [x, y].
        let padded = format!("({text})+0*x+0*y");
        let f = Expr::parse(&padded)
            .map_err(|e| bad(format!("cannot read the expression `{text}`: {e}")))?;
        if let Some(v) = f.var_names().iter().find(|v| *v != "x" && *v != "y") {
            return Err(bad(format!(
                "`{text}` uses `{v}`: a field may only use x and y (m), numbers, PI, E \
                 and functions such as sin, exp, sqrt"
            )));
        }
        let derivative = |i| {
            f.clone()
                .partial(i)
                .map_err(|e| bad(format!("cannot differentiate `{text}`: {e}")))
        };
        Ok(Scalar {
            key,
            parts: Some(Box::new([f.clone(), derivative(0)?, derivative(1)?])),
            uniform: 0.0,
        })
    }

    /// Part `k` (0: value, 1: ∂/∂x, 2: ∂/∂y) at (x, y) m.
    pub(crate) fn at(&self, k: usize, x: f64, y: f64) -> f64 {
        match &self.parts {
            None if k == 0 => self.uniform,
            None => 0.0,
            // Every part was parsed and checked with variables [x, y]: it evaluates.
            Some(p) => p[k].eval(&[x, y]).unwrap_or(f64::NAN),
        }
    }
}
