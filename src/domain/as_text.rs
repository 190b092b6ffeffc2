//! Serde for the values betr writes as text (conditions, atoms, actions, values, goal
//! formulas): each is written as the text a person types and read back through its own
//! parser, so a recording stays readable and a value read from a file is checked as typed
//! text is.

/// Serialize `$ty` with its `Display` and deserialize it with `$parse` (`&str` to
/// `Result<$ty, impl Display>`); a text that does not parse is an error quoting it.
macro_rules! serde_as_text {
    ($ty:ty, $parse:expr) => {
        impl serde::Serialize for $ty {
            fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
                s.collect_str(self)
            }
        }

        impl<'de> serde::Deserialize<'de> for $ty {
            fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
                let text = <String as serde::Deserialize>::deserialize(d)?;
                ($parse)(text.as_str())
                    .map_err(|e| serde::de::Error::custom(format!("{text:?}: {e}")))
            }
        }
    };
}

pub(crate) use serde_as_text;

#[cfg(test)]
mod tests {
    use crate::domain::{ActionCall, Atom, Condition, Value};
    use crate::goal::Formula;

    #[test]
    fn values_round_trip_through_their_text() {
        let c = Condition::parse("~\"red cube\" on \"blue cube\"").unwrap();
        let json = serde_json::to_string(&c).unwrap();
        assert_eq!(json, r#""~\"red cube\" on \"blue cube\"""#);
        assert_eq!(serde_json::from_str::<Condition>(&json).unwrap(), c);
        let a = ActionCall::parse("grasp \"egg\" {force = 5 N}").unwrap();
        let back: ActionCall = serde_json::from_str(&serde_json::to_string(&a).unwrap()).unwrap();
        assert_eq!(back, a);
        let f = Formula::parse("(A | B) & ~C").unwrap();
        let back: Formula = serde_json::from_str(&serde_json::to_string(&f).unwrap()).unwrap();
        assert_eq!(back, f);
        let atom = Atom::parse("\"cup\" in \"box\"").unwrap();
        let back: Atom = serde_json::from_str(&serde_json::to_string(&atom).unwrap()).unwrap();
        assert_eq!(back, atom);
        let v = crate::domain::action::parse_value("5 N").unwrap();
        let back: Value = serde_json::from_str(&serde_json::to_string(&v).unwrap()).unwrap();
        assert_eq!(back, v);
    }

    #[test]
    fn a_text_that_does_not_parse_is_an_error_quoting_it() {
        let e = serde_json::from_str::<Condition>(r#""on (""#).unwrap_err();
        assert!(e.to_string().contains("\"on (\""), "{e}");
    }
}
