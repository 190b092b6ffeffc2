use super::*;

use crate::scenario::Scenario;

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("betr-catalog-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn repo_scenarios() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios")
}

fn files_under(root: &Path, dir: &Path, out: &mut Vec<String>) {
    for e in std::fs::read_dir(dir).unwrap().flatten() {
        let p = e.path();
        if p.is_dir() {
            files_under(root, &p, out);
        } else {
            out.push(p.strip_prefix(root).unwrap().to_string_lossy().into_owned());
        }
    }
}

#[test]
fn every_file_of_the_scenarios_folder_is_shipped_as_it_is() {
    let root = repo_scenarios();
    let mut on_disk = Vec::new();
    files_under(&root, &root, &mut on_disk);
    on_disk.sort();
    let shipped: Vec<String> = SHIPPED.iter().map(|(rel, _)| rel.to_string()).collect();
    assert_eq!(shipped, on_disk);
    for (rel, text) in SHIPPED {
        assert_eq!(
            *text,
            std::fs::read_to_string(root.join(rel)).unwrap(),
            "{rel}"
        );
    }
}

#[test]
fn the_shipped_scenarios_load_from_the_data_directory() {
    let data = scratch("load");
    let done = install(&data).unwrap();
    assert_eq!(done.written.len(), SHIPPED.len());
    let catalog = Catalog {
        local: vec![data.join("no-such-folder")],
        data: Some(data.clone()),
    };
    let found = catalog.find(Path::new(DEFAULT_SCENARIO)).unwrap();
    assert_eq!(found, data.join("cell/red_on_blue.toml"));
    // `extends` and the example pool are found beside it.
    let scenario = Scenario::load(&found).unwrap();
    assert_eq!(scenario.name, "Red cube on the blue cube");
    assert!(scenario.examples.len() > 10);
    // A name without `.toml` works too.
    for name in ["cafe/no_coffee.toml", "cafe/no_coffee"] {
        assert_eq!(
            catalog.find(Path::new(name)).unwrap(),
            data.join("cafe/no_coffee.toml")
        );
    }
    std::fs::remove_dir_all(&data).unwrap();
}

#[test]
fn a_second_install_writes_nothing_and_a_changed_file_is_kept() {
    let data = scratch("again");
    install(&data).unwrap();
    assert_eq!(install(&data).unwrap(), Installed::default());

    // The person edits one file: a build shipping another version keeps theirs.
    let mine = "# my own cafe\n";
    std::fs::write(data.join("cafe/cafe.toml"), mine).unwrap();
    let done = install(&data).unwrap();
    assert_eq!(done.kept, vec!["cafe/cafe.toml".to_string()]);
    assert!(done.written.is_empty());
    assert_eq!(
        std::fs::read_to_string(data.join("cafe/cafe.toml")).unwrap(),
        mine
    );

    // A file betr wrote and nobody touched since is replaced by this build's version:
    // as if an older build had written `sweep.toml` differently.
    let old = "# an older betr's sweep\n";
    std::fs::write(data.join("cafe/sweep.toml"), old).unwrap();
    let manifest = std::fs::read_to_string(data.join(MANIFEST)).unwrap();
    let manifest: String = manifest
        .lines()
        .map(|l| match l.split_once("  ") {
            Some((_, "cafe/sweep.toml")) => {
                format!("{}  cafe/sweep.toml\n", sha256(old.as_bytes()))
            }
            _ => format!("{l}\n"),
        })
        .collect();
    std::fs::write(data.join(MANIFEST), manifest).unwrap();
    let done = install(&data).unwrap();
    assert_eq!(done.written, vec!["cafe/sweep.toml".to_string()]);
    assert_eq!(done.kept, vec!["cafe/cafe.toml".to_string()]);
    std::fs::remove_dir_all(&data).unwrap();
}

#[test]
fn a_scenario_of_ones_own_beside_the_shipped_ones_extends_them() {
    let data = scratch("own");
    install(&data).unwrap();
    let own = data.join("mine/two_cubes.toml");
    std::fs::create_dir_all(own.parent().unwrap()).unwrap();
    std::fs::write(
        &own,
        "extends = \"../cell/cell.toml\"\n[scenario]\nname = \"Two cubes\"\n\
         goal = '\"red cube\" on \"blue cube\"'\n[objects]\nitem = [\"red cube\", \"blue cube\"]\n",
    )
    .unwrap();
    let catalog = Catalog {
        local: Vec::new(),
        data: Some(data.clone()),
    };
    let found = catalog.find(Path::new("mine/two_cubes")).unwrap();
    assert_eq!(Scenario::load(&found).unwrap().name, "Two cubes");
    assert!(catalog.known().contains(&"mine/two_cubes".to_string()));
    std::fs::remove_dir_all(&data).unwrap();
}

#[test]
fn a_missing_scenario_names_each_place_once_and_the_scenarios_known() {
    let data = scratch("missing");
    let local = scratch("missing-local");
    let catalog = Catalog {
        local: vec![local.clone()],
        data: Some(data.clone()),
    };
    let err = catalog
        .find(Path::new("scenarios/cell/red_on_green.toml"))
        .unwrap_err();
    let CatalogError::NotFound {
        searched, known, ..
    } = &err
    else {
        panic!("{err}");
    };
    assert_eq!(
        searched,
        &vec![
            PathBuf::from("scenarios/cell/red_on_green.toml"),
            local.join("cell/red_on_green.toml"),
            data.join("cell/red_on_green.toml"),
        ]
    );
    assert!(known.contains(&"cell/red_on_blue".to_string()), "{known:?}");
    // Bases and example pools are not scenarios.
    assert!(
        !known
            .iter()
            .any(|k| k.ends_with("cell/cell") || k.ends_with("examples"))
    );
    let text = err.to_string();
    assert_eq!(text.matches("red_on_green").count(), 4, "{text}");
    std::fs::remove_dir_all(&data).unwrap();
    std::fs::remove_dir_all(&local).unwrap();
}

#[test]
fn a_name_is_looked_for_under_a_folder_without_its_leading_scenarios() {
    let root = Path::new("/d/betr/scenarios");
    assert_eq!(
        candidates(root, Path::new("scenarios/cell/x.toml")),
        vec![root.join("cell/x.toml")]
    );
    assert_eq!(
        candidates(root, Path::new("cell/x")),
        vec![root.join("cell/x"), root.join("cell/x.toml")]
    );
    assert!(candidates(root, Path::new("/abs/x.toml")).is_empty());
}

#[test]
fn the_data_directory_is_under_xdg_data_home_or_home() {
    let var = |k: &str| (k == "HOME").then(|| "/home/u".to_string());
    assert_eq!(
        data_dir(&var),
        Some(PathBuf::from("/home/u/.local/share/betr/scenarios"))
    );
    let var = |k: &str| match k {
        "XDG_DATA_HOME" => Some("/d".to_string()),
        _ => Some("/home/u".to_string()),
    };
    assert_eq!(data_dir(&var), Some(PathBuf::from("/d/betr/scenarios")));
}
