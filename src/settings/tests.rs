//! The settings' tests: parsing, overrides, and every declared domain enforced.

use super::*;
use crate::declare::{Domain, Section};
use crate::passes::hvl::{Distribution, GatherPath, RadiusHeuristic};
use crate::passes::igi::FilterMode;

#[test]
fn defaults_validate() {
    Settings::default().validate().unwrap();
    assert_eq!(Settings::from_toml_str("").unwrap(), Settings::default());
}

/// Each case breaks one field; the error must name it and its value.
#[test]
fn every_out_of_range_field_is_named() {
    type Edit = fn(&mut Settings);
    let cases: [(&str, &str, Edit); 29] = [
        ("proxy.sh_order", "7", |s| s.proxy.sh_order = 7),
        ("proxy.expansion", "1.0", |s| s.proxy.expansion = 1.0),
        ("proxy.indirect_expansion", "NaN", |s| {
            s.proxy.indirect_expansion = f32::NAN
        }),
        ("proxy.fit_count", "65", |s| s.proxy.fit_count = 65),
        ("width", "0", |s| s.width = 0),
        ("width", "16385", |s| s.width = 16385),
        ("height", "0", |s| s.height = 0),
        ("height", "20000", |s| s.height = 20000),
        ("frames", "0", |s| s.frames = 0),
        ("time", "-1.0", |s| s.time = -1.0),
        ("time", "NaN", |s| s.time = f32::NAN),
        ("receiver_scale", "3", |s| s.receiver_scale = 3),
        ("output.exposure", "0.0", |s| s.output.exposure = 0.0),
        ("output.exposure", "inf", |s| {
            s.output.exposure = f32::INFINITY
        }),
        ("hvl.count", "0", |s| s.hvl.count = 0),
        ("hvl.count", "10001", |s| s.hvl.count = 10001),
        ("hvl.count", "257", |s| {
            s.rsm.size = 16;
            s.hvl.count = 257;
        }),
        ("hvl.emission_bands", "3", |s| {
            s.hvl.conv_bands = 2;
            s.hvl.emission_bands = 3;
        }),
        ("hvl.radius_scale", "0.5", |s| s.hvl.radius_scale = 0.5),
        ("hvl.radius_scale", "2.5", |s| s.hvl.radius_scale = 2.5),
        ("hvl.convolution_bands", "100", |s| s.hvl.conv_bands = 100),
        ("hvl.emission_bands", "0", |s| s.hvl.emission_bands = 0),
        ("hvl.radius", "r1", |s| s.hvl.radius = RadiusHeuristic::R1),
        ("rsm.size", "8", |s| s.rsm.size = 8),
        ("shadow.size", "32", |s| s.shadow.size = 32),
        ("shadow.filter_radius", "-1.0", |s| {
            s.shadow.filter_radius = -1.0
        }),
        ("upsample.depth_epsilon", "0.0", |s| {
            s.upsample.depth_sigma = 0.0
        }),
        ("upsample.normal_power", "0.5", |s| {
            s.upsample.normal_power = 0.5
        }),
        ("upsample.normal_power", "1000.0", |s| {
            s.upsample.normal_power = 1000.0
        }),
    ];
    for (field, value, edit) in cases {
        let mut settings = Settings::default();
        edit(&mut settings);
        let message = settings.validate().unwrap_err().to_string();
        assert!(
            message.contains(&format!("`{field}` = {value}")),
            "{field}: {message}"
        );
        assert!(message.contains("allowed"), "{field}: {message}");
    }
}

#[test]
fn range_message_states_the_range() {
    let mut settings = Settings::default();
    settings.hvl.count = 10;
    assert_eq!(
        settings.validate().unwrap_err().to_string(),
        "setting `hvl.count` = 10 is out of range: allowed 64..=10000"
    );
}

#[test]
fn toml_round_trip() {
    let settings = Settings {
        width: 320,
        height: 200,
        time: 1.25,
        gi: GiTechniques::none(),
        receiver_scale: 4,
        output: OutputSettings {
            tonemap: Tonemap::Aces,
            exposure: 0.1,
            component: Component::Indirect,
            ssaa: 2,
            taa: true,
            auto_exposure: true,
            adaptation: 0.5,
        },
        hvl: HvlParams {
            radius: RadiusHeuristic::R1,
            distribution: Distribution::Grid,
            path: GatherPath::Zonal,
            ..HvlParams::default()
        },
        upsample: UpsampleParams {
            depth_sigma: 0.003,
            ..UpsampleParams::default()
        },
        ..Settings::default()
    };
    let text = settings.to_toml_string().unwrap();
    assert_eq!(Settings::from_toml_str(&text).unwrap(), settings);
}

#[test]
fn sections_parse() {
    let settings = Settings::from_toml_str(
        "width = 64\ngi = \"none\"\n[output]\ntonemap = \"aces\"\n[hvl]\ncount = 1000\n",
    )
    .unwrap();
    assert_eq!(settings.width, 64);
    assert!(settings.gi.is_none());
    assert_eq!(settings.output.tonemap, Tonemap::Aces);
    assert_eq!(settings.hvl.count, 1000);
    assert_eq!(settings.hvl.conv_bands, 5);
}

#[test]
fn files_load_and_errors_name_them() {
    let dir = std::env::temp_dir();
    let good = dir.join(format!("shine-settings-{}-good.toml", std::process::id()));
    let bad = dir.join(format!("shine-settings-{}-bad.toml", std::process::id()));
    std::fs::write(&good, "height = 64\n[rsm]\nsize = 256\n").unwrap();
    std::fs::write(&bad, "[shadow]\nsize = \"big\"\n").unwrap();
    let loaded = Settings::load(&good);
    let refused = Settings::load(&bad).unwrap_err().to_string();
    std::fs::remove_file(&good).unwrap();
    std::fs::remove_file(&bad).unwrap();
    let loaded = loaded.unwrap();
    assert_eq!((loaded.height, loaded.rsm.size), (64, 256));
    assert!(refused.contains(&bad.display().to_string()), "{refused}");
    assert!(refused.contains("size"), "{refused}");
    let missing = dir.join("shine-no-such-settings.toml");
    let message = Settings::load(&missing).unwrap_err().to_string();
    assert!(message.contains("shine-no-such-settings.toml"), "{message}");
}

#[test]
fn unknown_fields_are_rejected() {
    let top = Settings::from_toml_str("widht = 64")
        .unwrap_err()
        .to_string();
    assert!(top.contains("widht"), "{top}");
    let nested = Settings::from_toml_str("[hvl]\ncuont = 64")
        .unwrap_err()
        .to_string();
    assert!(nested.contains("cuont"), "{nested}");
    let section = Settings::from_toml_str("[hlv]\ncount = 64")
        .unwrap_err()
        .to_string();
    assert!(section.contains("hlv"), "{section}");
}

#[test]
fn float_ranges_keep_their_decimal_point() {
    let message = Settings::from_toml_str("[hvl]\nradius_scale = 2.5")
        .unwrap_err()
        .to_string();
    assert_eq!(
        message,
        "setting `hvl.radius_scale` = 2.5 is out of range: allowed 1.0..=2.0"
    );
}

#[test]
fn out_of_range_toml_is_rejected() {
    let message = Settings::from_toml_str("[hvl]\nconvolution_bands = 100")
        .unwrap_err()
        .to_string();
    assert!(message.contains("hvl.convolution_bands"), "{message}");
}

#[test]
fn unknown_choice_lists_the_known_names() {
    let message = Settings::from_toml_str("[output]\ntonemap = \"filmic\"")
        .unwrap_err()
        .to_string();
    assert!(message.contains("none, aces, pbr-neutral"), "{message}");
}

#[test]
fn the_sky_filter_radius_is_checked() {
    let message = Settings::from_toml_str("[sky]\nfilter_radius = 9")
        .unwrap_err()
        .to_string();
    assert!(message.contains("sky.filter_radius"), "{message}");
}

#[test]
fn cubes_are_refused_with_full_resolution_techniques() {
    for gi in ["igi", "aaf", "igi,proxy"] {
        let message = Settings::from_toml_str(&format!("gi = \"{gi}\"\n[cubes]\nenabled = true"))
            .unwrap_err()
            .to_string();
        assert!(message.contains("cubes.enabled"), "{gi}: {message}");
    }
    for gi in ["hvl", "proxy", "hvl,proxy", "none"] {
        let toml = format!("gi = \"{gi}\"\n[cubes]\nenabled = true\nlookup = \"texel\"");
        let settings = Settings::from_toml_str(&toml).unwrap();
        assert!(settings.cubes.enabled, "{gi}");
    }
}

#[test]
fn gi_lists_parse() {
    let both: GiTechniques = "hvl,proxy".parse().unwrap();
    assert_eq!(both.techniques(), [GiTechnique::Hvl, GiTechnique::Proxy]);
    assert_eq!(both.to_string(), "hvl,proxy");
    let hvl: GiTechniques = "hvl".parse().unwrap();
    assert_eq!(hvl.techniques(), [GiTechnique::Hvl]);
    assert!(hvl.contains(GiTechnique::Hvl));
    assert!("none".parse::<GiTechniques>().unwrap().is_none());
    assert_eq!(" hvl ".parse::<GiTechniques>().unwrap(), hvl);
    assert_eq!(hvl.to_string(), "hvl");
    assert_eq!(GiTechniques::none().to_string(), "none");
}

#[test]
fn gi_errors_are_clear() {
    let unknown = "hvl,foo".parse::<GiTechniques>().unwrap_err().to_string();
    assert!(unknown.contains("`foo`"), "{unknown}");
    assert!(unknown.contains("hvl, igi, proxy, aaf, none"), "{unknown}");
    for bad in ["", "hvl,", "none,hvl", "hvl,hvl"] {
        let message = bad.parse::<GiTechniques>().unwrap_err().to_string();
        assert!(
            message.contains("invalid GI technique list"),
            "{bad}: {message}"
        );
    }
    let both = Settings::from_toml_str("gi = \"hvl,aaf\"")
        .unwrap_err()
        .to_string();
    assert!(both.contains("choose one"), "{both}");
}

#[test]
fn aaf_settings_are_checked() {
    let aaf = Settings::from_toml_str("gi = \"aaf,proxy\"\n[aaf]\nmu = 2.0").unwrap();
    assert!(aaf.gi.contains(GiTechnique::Aaf));
    assert_eq!(aaf.aaf.mu, 2.0);
    type Edit = fn(&mut Settings);
    let cases: [(&str, &str, Edit); 6] = [
        ("aaf.mu", "0.0", |s| s.aaf.mu = 0.0),
        ("aaf.mu", "-1.0", |s| s.aaf.mu = -1.0),
        ("aaf.spp_min", "8", |s| s.aaf.spp_min = 8),
        ("aaf.omega_h", "0.0", |s| s.aaf.omega_h = 0.0),
        ("aaf.filter_degree", "3", |s| s.aaf.filter_degree = 3),
        ("aaf.spp_max", "8", |s| {
            s.aaf.spp_max = 8;
        }),
    ];
    for (field, value, edit) in cases {
        let mut settings = Settings::default();
        edit(&mut settings);
        let message = settings.validate().unwrap_err().to_string();
        assert!(
            message.contains(&format!("`{field}` = {value}")),
            "{field}: {message}"
        );
    }
}

#[test]
fn igi_settings_are_checked() {
    let igi =
        Settings::from_toml_str("gi = \"igi\"\n[igi]\nn = 2\nfilter = \"irradiance\"").unwrap();
    assert!(igi.gi.contains(GiTechnique::Igi));
    assert_eq!((igi.igi.n, igi.igi.mode), (2, FilterMode::Irradiance));
    type Edit = fn(&mut Settings);
    let cases: [(&str, &str, Edit); 8] = [
        ("igi.n", "0", |s| s.igi.n = 0),
        ("igi.m", "9", |s| s.igi.m = 9),
        ("igi.sh_order", "5", |s| s.igi.sh_order = 5),
        ("igi.sh_order", "1", |s| s.igi.sh_order = 1),
        ("igi.vpl_count", "10", |s| s.igi.vpl_count = 10),
        ("igi.filter_radius", "5", |s| s.igi.filter_radius = 5),
        ("igi.clamp_distance", "NaN", |s| {
            s.igi.clamp_distance = f32::NAN
        }),
        ("igi.vpl_count", "300", |s| {
            s.rsm.size = 16;
            s.hvl.count = 64;
            s.igi.vpl_count = 300;
        }),
    ];
    for (field, value, edit) in cases {
        let mut settings = Settings::default();
        edit(&mut settings);
        let message = settings.validate().unwrap_err().to_string();
        assert!(
            message.contains(&format!("`{field}` = {value}")),
            "{field}: {message}"
        );
    }
    let both = Settings::from_toml_str("gi = \"hvl,igi\"")
        .unwrap_err()
        .to_string();
    assert!(both.contains("choose one"), "{both}");
}

#[test]
fn overrides_apply_by_dotted_key() {
    let mut settings = Settings::default();
    settings.set("width", "640").unwrap();
    settings.set("hvl.count", "2000").unwrap();
    settings.set("hvl.radius_scale", "1.25").unwrap();
    settings.set("hvl.radius_scale", "2").unwrap();
    settings.set("output.tonemap", "aces").unwrap();
    settings.set("gi", "none").unwrap();
    assert_eq!(settings.width, 640);
    assert_eq!(settings.hvl.count, 2000);
    assert_eq!(settings.hvl.radius_scale, 2.0);
    assert_eq!(settings.output.tonemap, Tonemap::Aces);
    assert!(settings.gi.is_none());
    settings.validate().unwrap();
}

#[test]
fn bad_overrides_are_refused() {
    let mut settings = Settings::default();
    for (key, value) in [
        ("hvl.cuont", "5"),
        ("hvl", "5"),
        ("width.x", "5"),
        ("width", "wide"),
        ("width", "-3"),
        ("output.tonemap", "filmic"),
    ] {
        let message = settings.set(key, value).unwrap_err().to_string();
        assert!(message.contains(key), "{key}: {message}");
    }
    assert_eq!(settings, Settings::default());
    let message = settings.set("hvl.cuont", "5").unwrap_err().to_string();
    assert!(
        message.contains("no setting `cuont` in [hvl] (known: convolution_bands, count,"),
        "{message}"
    );
}

/// docs/settings.md is the page the declarations generate (`shine settings`).
#[test]
fn the_settings_page_is_current() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/docs/settings.md");
    let page = std::fs::read_to_string(path).unwrap();
    assert!(
        page == settings_page(),
        "docs/settings.md is stale: regenerate it with `cargo run --release -- settings > docs/settings.md`"
    );
}

/// The declarations list every setting once, none of the fields the frame fills in, and each
/// with a doc and a default in its domain.
#[test]
fn declarations_list_each_setting_once() {
    let specs = Settings::specs();
    let mut keys: Vec<&str> = specs.iter().map(|s| s.key.as_str()).collect();
    keys.sort_unstable();
    let count = keys.len();
    keys.dedup();
    assert_eq!(keys.len(), count, "a key is declared twice");
    for internal in [
        "aaf.seed",
        "aaf.storage_limit",
        "hvl.specular_limit",
        "hvl.near_radius",
    ] {
        assert!(
            !keys.contains(&internal),
            "{internal} is the frame's, not a setting"
        );
    }
    for key in [
        "aaf.samples",
        "hvl.convolution_bands",
        "igi.filter",
        "history.frames",
    ] {
        assert!(keys.contains(&key), "{key} missing");
    }
    for spec in &specs {
        assert!(!spec.doc.is_empty(), "{} has no doc", spec.key);
    }
}

/// The value of `spec`'s domain at one of its ends, as `--set` takes it, and one just outside.
fn ends(domain: &Domain) -> Vec<(String, bool)> {
    match domain {
        Domain::Int { min, max } => {
            let mut v = vec![(min.to_string(), true), (max.to_string(), true)];
            v.push(((max + 1).to_string(), false));
            if *min > 0 {
                v.push(((min - 1).to_string(), false));
            }
            v
        }
        Domain::Float { min, max } => vec![
            (format!("{min:?}"), true),
            (format!("{max:?}"), true),
            (format!("{:?}", max + max.abs().max(1.0)), false),
            ("nan".to_owned(), false),
        ],
        Domain::OneOf(values) => {
            let mut v: Vec<(String, bool)> = values.iter().map(|x| (x.to_string(), true)).collect();
            v.push(((values.iter().max().unwrap() + 1).to_string(), false));
            v
        }
        Domain::ZeroOr(inner) => {
            let mut v: Vec<(String, bool)> =
                ends(inner).into_iter().filter(|(x, _)| x != "0").collect();
            v.push(("0".to_owned(), true));
            v
        }
        Domain::Choice(names) => names.iter().map(|n| (format!("\"{n}\""), true)).collect(),
        Domain::Bool => vec![("true".to_owned(), true), ("false".to_owned(), true)],
        Domain::Text => Vec::new(),
    }
}

/// Validation is what the declarations say: every end of every declared domain is accepted
/// and every value just outside it is refused with the key named. The relations between
/// settings refuse a few in-domain ends against the other defaults; they are listed.
#[test]
fn every_declared_domain_is_enforced() {
    let relations = [
        // r1 radii need the grid; the default places HVLs by flux
        ("hvl.radius", "\"r1\""),
        // fewer convolution bands than the default emission's 3
        ("hvl.convolution_bands", "1"),
        // a 16² RSM holds fewer texels than the default 400 HVLs
        ("rsm.size", "16"),
    ];
    for spec in Settings::specs() {
        for (value, inside) in ends(&spec.domain) {
            let mut settings = Settings::default();
            settings.set(&spec.key, &value).unwrap();
            let checked = settings.validate();
            let related = relations.contains(&(spec.key.as_str(), value.as_str()));
            if related {
                assert!(
                    checked.is_err(),
                    "{} = {value} passed its relation",
                    spec.key
                );
            } else if inside {
                assert!(checked.is_ok(), "{} = {value}: {checked:?}", spec.key);
            } else {
                let message = match checked {
                    Err(e) => e.to_string(),
                    Ok(()) => panic!("{} = {value} is outside its domain but passed", spec.key),
                };
                assert!(
                    message.contains(&format!("`{}`", spec.key)),
                    "{} = {value}: {message}",
                    spec.key
                );
            }
        }
    }
}
