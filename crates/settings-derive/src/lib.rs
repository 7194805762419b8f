//! `#[derive(Settings)]`: each setting of shine declared once, on its field.
//!
//! A settings section is a serde struct (`#[serde(default, deny_unknown_fields)]`); serde
//! already gives it TOML, `--set` and its key names (`#[serde(rename)]`, `#[serde(skip)]` for
//! the parameters the frame fills in). This derive adds what serde does not know, from one
//! `#[setting(…)]` attribute per field:
//!
//! - `default = EXPR`: the field's default (the derive writes the `Default` impl);
//! - `range = EXPR` (a `RangeInclusive`), `one_of = EXPR` (a slice of allowed values) or
//!   `zero_or = EXPR` (0, or a value in the range): what validation accepts;
//! - `affects = cost | quality | both | output`: what the setting changes (the lab varies
//!   the first three; `output` only changes how the frame is written);
//! - `lab = EXPR` (a `RangeInclusive` inside the domain): the span the lab explores, where
//!   the domain's ends are far from useful (10 000 HVLs);
//! - `section`: the field is a nested section (its own `Settings` derive), defaulted,
//!   validated and listed under `key.`.
//!
//! On the struct, `#[settings(check = PATH)]` names a function `fn(&Self, prefix: &str) ->
//! Result<(), shine::declare::OutOfRange>` for the rules that tie fields together.
//!
//! The generated `Section` impl lists every setting (key, doc comment, domain, default,
//! effect) and checks every value; see `shine::declare` for the types it names.

use proc_macro::TokenStream;
use proc_macro2::TokenStream as Tokens;
use quote::{format_ident, quote};
use syn::{Attribute, Data, DeriveInput, Error, Expr, Fields, Ident, LitStr, Path};

/// Derives `Default` and `shine::declare::Section` from the fields' `#[setting]`
/// attributes (see the crate documentation).
#[proc_macro_derive(Settings, attributes(setting, settings))]
pub fn derive_settings(input: TokenStream) -> TokenStream {
    let input = syn::parse_macro_input!(input as DeriveInput);
    expand(&input)
        .unwrap_or_else(Error::into_compile_error)
        .into()
}

/// What validation accepts for one field.
enum Bound {
    /// Any value of the type (booleans, named choices).
    None,
    /// A `RangeInclusive`.
    Range(Expr),
    /// A slice of allowed values.
    OneOf(Expr),
    /// Zero, or a value in the range.
    ZeroOr(Expr),
}

/// One field's declaration, read from its attributes.
struct FieldDecl {
    ident: Ident,
    ty: syn::Type,
    key: String,
    doc: String,
    default: Option<Expr>,
    bound: Bound,
    affects: Option<Ident>,
    lab: Option<Expr>,
    section: bool,
    skip: bool,
}

fn expand(input: &DeriveInput) -> syn::Result<Tokens> {
    let name = &input.ident;
    let Data::Struct(data) = &input.data else {
        return Err(Error::new_spanned(name, "Settings derives only on structs"));
    };
    let Fields::Named(fields) = &data.fields else {
        return Err(Error::new_spanned(name, "Settings needs named fields"));
    };
    let check = struct_check(&input.attrs)?;
    let decls = fields
        .named
        .iter()
        .map(field_decl)
        .collect::<syn::Result<Vec<_>>>()?;

    let mut defaults = Vec::new();
    let mut specs = Vec::new();
    let mut checks = Vec::new();
    for d in &decls {
        let ident = &d.ident;
        let key = &d.key;
        if d.section {
            defaults.push(quote! { #ident: ::core::default::Default::default() });
            let nested = format!("{key}.");
            let ty = &d.ty;
            specs.push(quote! {
                <#ty as crate::declare::Section>::specs_into(
                    &::std::format!("{prefix}{}", #nested), out);
            });
            checks.push(quote! {
                crate::declare::Section::check_in(
                    &self.#ident, &::std::format!("{prefix}{}", #nested))?;
            });
            continue;
        }
        let Some(default) = &d.default else {
            return Err(Error::new_spanned(
                ident,
                "every field needs `#[setting(default = …)]` (or `section`)",
            ));
        };
        defaults.push(quote! { #ident: #default });
        if d.skip {
            continue;
        }
        let Some(affects) = &d.affects else {
            return Err(Error::new_spanned(
                ident,
                "a setting needs `affects = cost | quality | both | output`",
            ));
        };
        let affects = format_ident!(
            "{}",
            match affects.to_string().as_str() {
                "cost" => "Cost",
                "quality" => "Quality",
                "both" => "Both",
                "output" => "Output",
                _ => {
                    return Err(Error::new_spanned(
                        affects,
                        "`affects` is one of cost, quality, both, output",
                    ));
                }
            }
        );
        let doc = &d.doc;
        let (domain, check) = match &d.bound {
            Bound::None => (
                quote! { crate::declare::SettingValue::domain(&defaults.#ident) },
                None,
            ),
            Bound::Range(r) => (
                quote! { crate::declare::Domain::range(&(#r)) },
                Some(quote! { crate::declare::check_range(prefix, #key, &self.#ident, &(#r))?; }),
            ),
            Bound::OneOf(l) => (
                quote! { crate::declare::Domain::one_of(&(#l)) },
                Some(quote! { crate::declare::check_one_of(prefix, #key, self.#ident, &(#l))?; }),
            ),
            Bound::ZeroOr(r) => (
                quote! { crate::declare::Domain::zero_or(&(#r)) },
                Some(quote! { crate::declare::check_zero_or(prefix, #key, &self.#ident, &(#r))?; }),
            ),
        };
        let lab = match &d.lab {
            Some(r) => {
                quote! { ::core::option::Option::Some(crate::declare::Domain::range(&(#r))) }
            }
            None => quote! { ::core::option::Option::None },
        };
        specs.push(quote! {
            out.push(crate::declare::ParamSpec {
                key: ::std::format!("{prefix}{}", #key),
                doc: #doc,
                domain: #domain,
                lab: #lab,
                default: crate::declare::to_value(&defaults.#ident),
                affects: crate::declare::Affects::#affects,
            });
        });
        checks.extend(check);
    }
    let relation = check.map(|path| quote! { #path(self, prefix)?; });
    Ok(quote! {
        impl ::core::default::Default for #name {
            fn default() -> Self {
                Self { #(#defaults,)* }
            }
        }

        impl crate::declare::Section for #name {
            fn specs_into(
                prefix: &str,
                out: &mut ::std::vec::Vec<crate::declare::ParamSpec>,
            ) {
                let defaults = <Self as ::core::default::Default>::default();
                #(#specs)*
            }

            fn check_in(&self, prefix: &str) -> ::core::result::Result<(), crate::declare::OutOfRange> {
                #(#checks)*
                #relation
                ::core::result::Result::Ok(())
            }
        }
    })
}

/// The struct's `#[settings(check = PATH)]`, if any.
fn struct_check(attrs: &[Attribute]) -> syn::Result<Option<Path>> {
    let mut check = None;
    for attr in attrs.iter().filter(|a| a.path().is_ident("settings")) {
        attr.parse_nested_meta(|meta| {
            if meta.path.is_ident("check") {
                check = Some(meta.value()?.parse::<Path>()?);
                Ok(())
            } else {
                Err(meta.error("expected `check = PATH`"))
            }
        })?;
    }
    Ok(check)
}

/// Reads a field's `#[setting]`, `#[serde]` and doc attributes.
fn field_decl(field: &syn::Field) -> syn::Result<FieldDecl> {
    let Some(ident) = field.ident.clone() else {
        return Err(Error::new_spanned(field, "Settings needs named fields"));
    };
    let attrs = &field.attrs;
    let mut decl = FieldDecl {
        ty: field.ty.clone(),
        key: ident.to_string(),
        ident,
        doc: String::new(),
        default: None,
        bound: Bound::None,
        affects: None,
        lab: None,
        section: false,
        skip: false,
    };
    let mut lines = Vec::new();
    for attr in attrs {
        if attr.path().is_ident("doc") {
            if let syn::Meta::NameValue(nv) = &attr.meta
                && let Expr::Lit(lit) = &nv.value
                && let syn::Lit::Str(s) = &lit.lit
            {
                lines.push(s.value().trim().to_owned());
            }
        } else if attr.path().is_ident("serde") {
            attr.parse_nested_meta(|meta| {
                if meta.path.is_ident("rename") {
                    decl.key = meta.value()?.parse::<LitStr>()?.value();
                } else if meta.path.is_ident("skip") || meta.path.is_ident("skip_deserializing") {
                    decl.skip = true;
                } else if meta.input.peek(syn::Token![=]) {
                    meta.value()?.parse::<Expr>()?;
                } else if meta.input.peek(syn::token::Paren) {
                    meta.parse_nested_meta(|inner| {
                        if inner.input.peek(syn::Token![=]) {
                            inner.value()?.parse::<Expr>()?;
                        }
                        Ok(())
                    })?;
                }
                Ok(())
            })?;
        } else if attr.path().is_ident("setting") {
            attr.parse_nested_meta(|meta| {
                let set_bound = |decl: &mut FieldDecl, bound: Bound| {
                    if !matches!(decl.bound, Bound::None) {
                        return Err(meta.error("one of `range`, `one_of`, `zero_or`"));
                    }
                    decl.bound = bound;
                    Ok(())
                };
                if meta.path.is_ident("default") {
                    decl.default = Some(meta.value()?.parse()?);
                } else if meta.path.is_ident("range") {
                    set_bound(&mut decl, Bound::Range(meta.value()?.parse()?))?;
                } else if meta.path.is_ident("one_of") {
                    set_bound(&mut decl, Bound::OneOf(meta.value()?.parse()?))?;
                } else if meta.path.is_ident("zero_or") {
                    set_bound(&mut decl, Bound::ZeroOr(meta.value()?.parse()?))?;
                } else if meta.path.is_ident("lab") {
                    decl.lab = Some(meta.value()?.parse()?);
                } else if meta.path.is_ident("affects") {
                    decl.affects = Some(meta.value()?.parse()?);
                } else if meta.path.is_ident("section") {
                    decl.section = true;
                } else {
                    return Err(
                        meta.error("expected default, range, one_of, zero_or, affects or section")
                    );
                }
                Ok(())
            })?;
        }
    }
    decl.doc = one_line(&lines);
    Ok(decl)
}

/// The doc comment's lines as one line (paragraphs joined by a space).
fn one_line(lines: &[String]) -> String {
    lines
        .iter()
        .filter(|l| !l.is_empty())
        .cloned()
        .collect::<Vec<_>>()
        .join(" ")
}
