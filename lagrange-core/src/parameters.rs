//! [`parameters!`](crate::parameters): a mechanism's parameter struct, its validated
//! constructor, its accessors and its defaults, from one list: the plumbing every generated
//! mechanism (and many hand-written ones) would otherwise repeat.

/// Defines a mechanism's struct, generic over `T: Real`, from its parameters (each with its
/// docs, its kind and its default) and the quantities its constructor forms from them once:
///
/// ```text
/// parameters! {
///     /// The struct's docs.
///     pub struct Name {
///         /// A parameter's docs (also its accessor's).
///         name: kind = default,
///         ...
///     }
///     formed {
///         /// A formed quantity's docs.
///         name: Type = expression of the parameters,
///         ...
///     }
/// }
/// ```
///
/// `kind` is a function of [`validate`](crate::validate) that takes the parameter's name and
/// value: `positive`, `non_negative` or `finite`. The `formed` block is optional; its
/// expressions see the parameters by name (and `T`), and each may use the ones before it.
/// The macro writes:
///
/// - the struct (`Debug`, `Clone`, `Copy`, `PartialEq`), parameters first, then the formed
///   fields, all private;
/// - `new(parameters...) -> Result<Self, Error>`, which checks each parameter with its kind,
///   in order, and returns the first [`Error::InvalidParameter`](crate::Error::InvalidParameter)
///   (naming it) or the mechanism;
/// - an accessor per parameter, `name(&self) -> T`, with the parameter's docs;
/// - [`Default`], from the defaults (which are not checked: give valid ones).
///
/// Unused accessors and constructors are not warned about (`dead_code` is allowed on them): a
/// mechanism's API is there whether or not a program calls all of it.
///
/// ```
/// use lagrange_core::{parameters, Error, Real};
///
/// parameters! {
///     /// A pendulum.
///     pub struct Pendulum {
///         /// Rod length, m.
///         l: positive = 1.0,
///         /// Gravity, m/s^2.
///         g: non_negative = 9.81,
///     }
///     formed {
///         /// `g / l`.
///         rate: T = g / l,
///     }
/// }
///
/// let p = Pendulum::<f64>::new(2.0, 9.81)?;
/// assert_eq!((p.l(), p.g()), (2.0, 9.81));
/// assert_eq!(Pendulum::<f32>::default().l(), 1.0);
/// let refused = Pendulum::new(-1.0, 9.81);
/// assert!(matches!(refused, Err(Error::InvalidParameter { name: "l", .. })));
/// # Ok::<(), Error>(())
/// ```
#[macro_export]
macro_rules! parameters {
    (
        $(#[$attr:meta])*
        $vis:vis struct $name:ident {
            $(
                $(#[$pattr:meta])*
                $p:ident : $kind:ident = $default:expr
            ),+ $(,)?
        }
        $(
            formed {
                $(
                    $(#[$kattr:meta])*
                    $k:ident : $kty:ty = $kexpr:expr
                ),* $(,)?
            }
        )?
    ) => {
        $(#[$attr])*
        #[derive(Debug, Clone, Copy, PartialEq)]
        $vis struct $name<T: $crate::Real> {
            $(
                $(#[$pattr])*
                $p: T,
            )+
            $($(
                $(#[$kattr])*
                $k: $kty,
            )*)?
        }

        #[allow(dead_code)]
        impl<T: $crate::Real> $name<T> {
            /// The mechanism of these parameters, each checked by its kind (a function of
            /// `lagrange_core::validate`), in this order:
            ///
            $(
                #[doc = concat!("- `", stringify!($p), "`: ", stringify!($kind))]
            )+
            ///
            /// # Errors
            /// `Error::InvalidParameter` naming the first parameter out of its range or not
            /// finite.
            #[allow(clippy::too_many_arguments)]
            $vis fn new($($p: T),+) -> ::core::result::Result<Self, $crate::Error> {
                ::core::result::Result::Ok(Self::from_valid(
                    $($crate::validate::$kind(stringify!($p), $p)?),+
                ))
            }

            /// The mechanism of parameters already checked, its formed quantities formed once.
            #[allow(clippy::too_many_arguments)]
            fn from_valid($($p: T),+) -> Self {
                $($(
                    let $k: $kty = $kexpr;
                )*)?
                Self {
                    $($p,)+
                    $($($k,)*)?
                }
            }

            $(
                $(#[$pattr])*
                #[must_use]
                $vis fn $p(&self) -> T {
                    self.$p
                }
            )+
        }

        impl<T: $crate::Real> ::core::default::Default for $name<T> {
            /// The defaults:
            ///
            $(
                #[doc = concat!("- `", stringify!($p), "` = ", stringify!($default))]
            )+
            fn default() -> Self {
                Self::from_valid($(<T as $crate::Scalar>::from_f64($default)),+)
            }
        }
    };
}
