//! `cargo xtask import-circles`: no module of any crate depends on itself through others.
//!
//! Each crate's modules are found from its roots (`src/lib.rs`, `src/main.rs`, `src/bin/*.rs`)
//! along their `mod` declarations, and module A depends on module B where A names an item of B:
//! a `use` of `crate::…`, `super::…`, `self::…` or a child module, or such a path written in A's
//! code. A path stands for the deepest module it passes through (`crate::order::near::Grid` is
//! `order::near`; `crate::plan_job` is the crate's root). Test code (`#[cfg(test)]` items) is
//! left out: a test module reaching up into what it tests is not a layer. A glob (`use super::*`)
//! depends on the module it imports from; an inline `mod name { … }` is a module of its own, its
//! files (if any) found under the directory its name adds. A circle is a strongly connected set
//! of two or more modules; each is reported with one cycle through it and the file that closes
//! each step.
//!
//! Limits of reading syntax rather than resolved names: paths written inside macro invocations
//! (`format!`, `vec!`, `assert!`, …) are token streams the visitor does not see, so a dependency
//! named only there is missed; a method call names no path, so calling a method that another
//! module's `impl` block defines is not seen (the `impl` block's own module depends on the
//! type's); a path that starts with a name brought in by `use` is counted through that `use`;
//! `#[path]` attributes and modules declared inside function bodies are not followed;
//! `#[cfg(test)]` is recognized in that exact form only.

use std::collections::{BTreeMap, BTreeSet, VecDeque};
use std::fmt;
use std::path::{Path, PathBuf};

use anyhow::{Context, bail};
use syn::visit::Visit;

use crate::workspace;

/// Arguments of `cargo xtask import-circles`.
#[derive(clap::Args)]
pub struct Args {
    /// Workspace to check (default: this one).
    #[arg(long)]
    pub root: Option<PathBuf>,
}

/// Checks every crate of the workspace and fails, listing each circle, where one is found.
pub fn run(args: &Args) -> anyhow::Result<()> {
    let root = args.root.clone().unwrap_or_else(workspace::root);
    let circles = workspace_circles(&root)?;
    if circles.is_empty() {
        println!("no import circles between the modules of any crate");
        return Ok(());
    }
    for circle in &circles {
        println!("{circle}");
    }
    bail!("{} import circle(s) between modules", circles.len())
}

/// A module, by its path from the crate root (empty for the root itself).
type ModulePath = Vec<String>;

/// One module of a crate: where it is written and what it depends on.
struct Module {
    file: PathBuf,
    /// Paths it names, resolved from the crate root (before mapping onto modules).
    named: Vec<ModulePath>,
}

/// A set of modules of one crate that depend on each other in a circle.
#[derive(Debug)]
pub struct Circle {
    crate_root: PathBuf,
    /// Every module of the set.
    members: Vec<ModulePath>,
    /// One cycle through the set: each module depends on the next, the last on the first.
    cycle: Vec<(ModulePath, PathBuf)>,
}

impl fmt::Display for Circle {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let members: Vec<String> = self.members.iter().map(display_module).collect();
        writeln!(
            f,
            "import circle in {} between {}; one cycle:",
            self.crate_root.display(),
            members.join(", ")
        )?;
        for (k, (module, file)) in self.cycle.iter().enumerate() {
            let next = &self.cycle[(k + 1) % self.cycle.len()].0;
            writeln!(
                f,
                "  {} ({}) uses {}",
                display_module(module),
                file.display(),
                display_module(next)
            )?;
        }
        Ok(())
    }
}

fn display_module(module: &ModulePath) -> String {
    if module.is_empty() {
        "crate".to_string()
    } else {
        format!("crate::{}", module.join("::"))
    }
}

/// The circles of every crate under `root/crates/*` and of `root/xtask`.
pub fn workspace_circles(root: &Path) -> anyhow::Result<Vec<Circle>> {
    let mut packages = vec![root.join("xtask")];
    let crates = root.join("crates");
    let mut members: Vec<PathBuf> = std::fs::read_dir(&crates)
        .with_context(|| format!("reading {}", crates.display()))?
        .map(|entry| entry.map(|e| e.path()))
        .collect::<Result<_, _>>()?;
    members.sort();
    packages.extend(members);
    let mut circles = Vec::new();
    for package in packages {
        for crate_root in crate_roots(&package.join("src"))? {
            circles.extend(crate_circles(&crate_root)?);
        }
    }
    Ok(circles)
}

/// The root files of a package's crates: its library, its main binary and `src/bin/*.rs`.
fn crate_roots(src: &Path) -> anyhow::Result<Vec<PathBuf>> {
    let mut roots: Vec<PathBuf> = ["lib.rs", "main.rs"]
        .iter()
        .map(|name| src.join(name))
        .filter(|path| path.is_file())
        .collect();
    let bin = src.join("bin");
    if bin.is_dir() {
        let mut binaries: Vec<PathBuf> = std::fs::read_dir(&bin)?
            .map(|entry| entry.map(|e| e.path()))
            .collect::<Result<Vec<_>, _>>()?
            .into_iter()
            .filter(|path| path.extension().is_some_and(|ext| ext == "rs"))
            .collect();
        binaries.sort();
        roots.extend(binaries);
    }
    Ok(roots)
}

/// The circles between the modules of the crate whose root file is `crate_root`.
pub fn crate_circles(crate_root: &Path) -> anyhow::Result<Vec<Circle>> {
    let modules = read_crate(crate_root)?;
    let mut edges: BTreeMap<&ModulePath, BTreeSet<&ModulePath>> = BTreeMap::new();
    for (path, module) in &modules {
        let targets = edges.entry(path).or_default();
        for named in &module.named {
            let target = deepest_module(&modules, named);
            if target != path {
                targets.insert(target);
            }
        }
    }
    Ok(strongly_connected(&edges)
        .into_iter()
        .filter(|set| set.len() > 1)
        .map(|set| Circle {
            crate_root: crate_root.to_path_buf(),
            members: set.iter().map(|&module| module.clone()).collect(),
            cycle: shortest_cycle(&edges, &set)
                .into_iter()
                .map(|module| (module.clone(), modules[module].file.clone()))
                .collect(),
        })
        .collect())
}

/// The deepest module of `modules` that `path` passes through.
fn deepest_module<'a>(
    modules: &'a BTreeMap<ModulePath, Module>,
    path: &ModulePath,
) -> &'a ModulePath {
    (0..=path.len())
        .rev()
        .find_map(|len| modules.get_key_value(&path[..len]).map(|(key, _)| key))
        .expect("the crate root is a module")
}

/// Every module of a crate, read from its root file along its `mod` declarations.
fn read_crate(crate_root: &Path) -> anyhow::Result<BTreeMap<ModulePath, Module>> {
    let mut modules = BTreeMap::new();
    let dir = crate_root.parent().expect("a root file lies in src/");
    read_file_module(crate_root, dir, Vec::new(), &mut modules)?;
    Ok(modules)
}

/// Reads the module written in `file`, whose child module files lie in `child_dir`.
fn read_file_module(
    file: &Path,
    child_dir: &Path,
    path: ModulePath,
    modules: &mut BTreeMap<ModulePath, Module>,
) -> anyhow::Result<()> {
    let text =
        std::fs::read_to_string(file).with_context(|| format!("reading {}", file.display()))?;
    let syntax = syn::parse_file(&text).with_context(|| format!("parsing {}", file.display()))?;
    read_items(&syntax.items, file, child_dir, path, modules)
}

/// Records the module `path` made of `items` and every module it declares.
fn read_items(
    items: &[syn::Item],
    file: &Path,
    child_dir: &Path,
    path: ModulePath,
    modules: &mut BTreeMap<ModulePath, Module>,
) -> anyhow::Result<()> {
    let mut children = BTreeSet::new();
    let mut nested = Vec::new();
    let mut code = Vec::new();
    for item in items.iter().filter(|item| !is_test_only(item)) {
        match item {
            syn::Item::Mod(declared) => {
                children.insert(declared.ident.to_string());
                nested.push(declared);
            }
            other => code.push(other),
        }
    }
    let mut names = NamedPaths {
        module: &path,
        children: &children,
        named: Vec::new(),
    };
    for item in code {
        names.visit_item(item);
    }
    let named = names.named;
    modules.insert(
        path.clone(),
        Module {
            file: file.to_path_buf(),
            named,
        },
    );
    for declared in nested {
        let name = declared.ident.to_string();
        let mut child = path.clone();
        child.push(name.clone());
        match &declared.content {
            Some((_, items)) => read_items(items, file, &child_dir.join(&name), child, modules)?,
            None => {
                let flat = child_dir.join(format!("{name}.rs"));
                let (child_file, grandchild_dir) = if flat.is_file() {
                    (flat, child_dir.join(&name))
                } else {
                    let nested_file = child_dir.join(&name).join("mod.rs");
                    (nested_file, child_dir.join(&name))
                };
                read_file_module(&child_file, &grandchild_dir, child, modules)?;
            }
        }
    }
    Ok(())
}

/// Whether an item is compiled only for tests (`#[cfg(test)]`).
fn is_test_only(item: &syn::Item) -> bool {
    item_attrs(item).is_some_and(has_cfg_test)
}

/// The attributes of an item, where it is a kind that can carry `#[cfg(test)]`.
fn item_attrs(item: &syn::Item) -> Option<&[syn::Attribute]> {
    let attrs: &[syn::Attribute] = match item {
        syn::Item::Mod(item) => &item.attrs,
        syn::Item::Use(item) => &item.attrs,
        syn::Item::Fn(item) => &item.attrs,
        syn::Item::Impl(item) => &item.attrs,
        syn::Item::Struct(item) => &item.attrs,
        syn::Item::Enum(item) => &item.attrs,
        syn::Item::Const(item) => &item.attrs,
        syn::Item::Static(item) => &item.attrs,
        syn::Item::Trait(item) => &item.attrs,
        syn::Item::Type(item) => &item.attrs,
        syn::Item::Macro(item) => &item.attrs,
        _ => return None,
    };
    Some(attrs)
}

/// Whether `attrs` hold `#[cfg(test)]`.
fn has_cfg_test(attrs: &[syn::Attribute]) -> bool {
    attrs.iter().any(|attr| {
        attr.path().is_ident("cfg")
            && attr
                .parse_args::<syn::Ident>()
                .is_ok_and(|ident| ident == "test")
    })
}

/// The paths of the crate's own items that one module's code names.
struct NamedPaths<'a> {
    module: &'a ModulePath,
    children: &'a BTreeSet<String>,
    named: Vec<ModulePath>,
}

impl NamedPaths<'_> {
    /// `segments` resolved from the crate root, or `None` where they start outside the crate.
    fn resolve(&self, segments: &[String]) -> Option<ModulePath> {
        let (first, rest) = segments.split_first()?;
        let mut base = match first.as_str() {
            "crate" => Vec::new(),
            "self" => self.module.clone(),
            "super" => {
                let mut parent = self.module.clone();
                parent.pop();
                parent
            }
            child if self.children.contains(child) => {
                let mut path = self.module.clone();
                path.push(child.to_string());
                path
            }
            _ => return None,
        };
        let mut rest = rest.iter().peekable();
        while rest.peek().is_some_and(|segment| *segment == "super") {
            base.pop();
            rest.next();
        }
        base.extend(rest.cloned());
        Some(base)
    }

    /// Records the path `segments`, where it names an item of the crate.
    fn name(&mut self, segments: &[String]) {
        if let Some(path) = self.resolve(segments) {
            self.named.push(path);
        }
    }

    /// Records every path a `use` tree under `prefix` names (a glob: the module it imports from).
    fn use_tree(&mut self, prefix: &mut Vec<String>, tree: &syn::UseTree) {
        match tree {
            syn::UseTree::Path(path) => {
                prefix.push(path.ident.to_string());
                self.use_tree(prefix, &path.tree);
                prefix.pop();
            }
            syn::UseTree::Name(name) => {
                prefix.push(name.ident.to_string());
                self.name(prefix);
                prefix.pop();
            }
            syn::UseTree::Rename(rename) => {
                prefix.push(rename.ident.to_string());
                self.name(prefix);
                prefix.pop();
            }
            syn::UseTree::Glob(_) => self.name(prefix),
            syn::UseTree::Group(group) => {
                for tree in &group.items {
                    self.use_tree(prefix, tree);
                }
            }
        }
    }
}

impl<'ast> Visit<'ast> for NamedPaths<'_> {
    fn visit_item(&mut self, item: &'ast syn::Item) {
        if !is_test_only(item) {
            syn::visit::visit_item(self, item);
        }
    }

    fn visit_impl_item_fn(&mut self, item: &'ast syn::ImplItemFn) {
        if !has_cfg_test(&item.attrs) {
            syn::visit::visit_impl_item_fn(self, item);
        }
    }

    fn visit_item_use(&mut self, item: &'ast syn::ItemUse) {
        self.use_tree(&mut Vec::new(), &item.tree);
    }

    fn visit_vis_restricted(&mut self, _: &'ast syn::VisRestricted) {
        // `pub(in crate::a)` says who may see an item, not what the item uses.
    }

    fn visit_item_mod(&mut self, _: &'ast syn::ItemMod) {
        // A module declared inside a function body is its own module; none are written so.
    }

    fn visit_path(&mut self, path: &'ast syn::Path) {
        if path.segments.len() > 1 {
            let segments: Vec<String> = path
                .segments
                .iter()
                .map(|segment| segment.ident.to_string())
                .collect();
            self.name(&segments);
        }
        syn::visit::visit_path(self, path);
    }
}

/// Tarjan's strongly connected components of a graph.
fn strongly_connected<'a>(
    edges: &BTreeMap<&'a ModulePath, BTreeSet<&'a ModulePath>>,
) -> Vec<BTreeSet<&'a ModulePath>> {
    struct State<'a> {
        index: BTreeMap<&'a ModulePath, usize>,
        low: BTreeMap<&'a ModulePath, usize>,
        stack: Vec<&'a ModulePath>,
        on_stack: BTreeSet<&'a ModulePath>,
        sets: Vec<BTreeSet<&'a ModulePath>>,
    }
    fn connect<'a>(
        node: &'a ModulePath,
        edges: &BTreeMap<&'a ModulePath, BTreeSet<&'a ModulePath>>,
        state: &mut State<'a>,
    ) {
        let index = state.index.len();
        state.index.insert(node, index);
        state.low.insert(node, index);
        state.stack.push(node);
        state.on_stack.insert(node);
        for &next in edges.get(node).into_iter().flatten() {
            if !state.index.contains_key(next) {
                connect(next, edges, state);
                let low = state.low[node].min(state.low[next]);
                state.low.insert(node, low);
            } else if state.on_stack.contains(next) {
                let low = state.low[node].min(state.index[next]);
                state.low.insert(node, low);
            }
        }
        if state.low[node] == state.index[node] {
            let mut set = BTreeSet::new();
            while let Some(member) = state.stack.pop() {
                state.on_stack.remove(member);
                set.insert(member);
                if member == node {
                    break;
                }
            }
            state.sets.push(set);
        }
    }
    let mut state = State {
        index: BTreeMap::new(),
        low: BTreeMap::new(),
        stack: Vec::new(),
        on_stack: BTreeSet::new(),
        sets: Vec::new(),
    };
    for &node in edges.keys() {
        if !state.index.contains_key(node) {
            connect(node, edges, &mut state);
        }
    }
    state.sets
}

/// The shortest cycle through the first module of `set` that stays inside `set`.
fn shortest_cycle<'a>(
    edges: &BTreeMap<&'a ModulePath, BTreeSet<&'a ModulePath>>,
    set: &BTreeSet<&'a ModulePath>,
) -> Vec<&'a ModulePath> {
    let start = *set.first().expect("a circle has members");
    let mut came_from: BTreeMap<&ModulePath, &ModulePath> = BTreeMap::new();
    let mut queue = VecDeque::from([start]);
    while let Some(node) = queue.pop_front() {
        for &next in edges.get(node).into_iter().flatten() {
            if !set.contains(next) {
                continue;
            }
            if next == start {
                let mut cycle = vec![node];
                while let Some(&before) = came_from.get(cycle.last().expect("not empty")) {
                    cycle.push(before);
                }
                cycle.reverse();
                return cycle;
            }
            if let std::collections::btree_map::Entry::Vacant(entry) = came_from.entry(next) {
                entry.insert(node);
                queue.push_back(next);
            }
        }
    }
    unreachable!("every member of a strongly connected set lies on a cycle through the first")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A crate's sources in a temporary directory, its root `lib.rs`.
    struct Sources(tempfile::TempDir);

    impl Sources {
        fn new() -> Self {
            Self(tempfile::tempdir().unwrap())
        }

        /// Writes `text` as the source file `name`.
        fn write(&self, name: &str, text: &str) {
            let path = self.0.path().join(name);
            std::fs::create_dir_all(path.parent().unwrap()).unwrap();
            std::fs::write(path, text).unwrap();
        }

        /// The import circles of the crate.
        fn circles(&self) -> Vec<Circle> {
            crate_circles(&self.0.path().join("lib.rs")).unwrap()
        }

        /// The crate's one import circle.
        fn only_circle(&self) -> Circle {
            let mut circles = self.circles();
            assert_eq!(circles.len(), 1, "{circles:?}");
            circles.remove(0)
        }
    }

    #[test]
    fn a_module_reaching_back_to_the_root_is_a_circle_and_test_code_is_not() {
        let src = Sources::new();
        src.write("lib.rs", "mod a;\nmod b;\npub use a::Thing;\n");
        src.write(
            "a.rs",
            "pub struct Thing;\nfn f() -> usize { crate::b::ONE }\n",
        );
        src.write(
            "b.rs",
            "pub const ONE: usize = 1;\n#[cfg(test)]\nmod tests { use crate::a::Thing; }\n",
        );
        assert!(src.circles().is_empty());

        src.write("b.rs", "pub const ONE: usize = 1;\nuse crate::Thing;\n");
        let members: Vec<String> = src
            .only_circle()
            .cycle
            .iter()
            .map(|(module, _)| display_module(module))
            .collect();
        assert_eq!(members, ["crate", "crate::a", "crate::b"]);
    }

    #[test]
    fn child_and_super_paths_resolve_to_their_modules() {
        let src = Sources::new();
        src.write("lib.rs", "mod order;\nmod tour;\n");
        src.write("order.rs", "mod near;\npub fn f() { near::g() }\n");
        src.write("order/near.rs", "pub fn g() { super::super::tour::h() }\n");
        src.write("tour.rs", "pub fn h() {}\n");
        assert!(src.circles().is_empty());

        src.write("tour.rs", "pub fn h() {}\nfn i() { crate::order::f() }\n");
        let circle = src.only_circle();
        assert_eq!(circle.cycle.len(), 3, "{circle}");
    }

    #[test]
    fn globs_inline_modules_and_test_code_inside_items() {
        let src = Sources::new();
        src.write(
            "lib.rs",
            "mod outer {\n    pub mod inner;\n    pub fn f() { inner::g() }\n}\n",
        );
        src.write(
            "outer/inner.rs",
            concat!(
                "pub(in crate::outer) fn g() {}\n",
                "struct T;\n",
                "impl T {\n    #[cfg(test)]\n    fn t() { crate::outer::f() }\n}\n",
                "#[cfg(test)]\nmod tests { use super::super::*; }\n",
            ),
        );
        assert!(src.circles().is_empty());

        src.write("outer/inner.rs", "use super::*;\npub fn g() {}\n");
        let members: Vec<String> = src
            .only_circle()
            .members
            .iter()
            .map(display_module)
            .collect();
        assert_eq!(members, ["crate::outer", "crate::outer::inner"]);
    }

    #[test]
    fn no_crate_of_the_workspace_has_an_import_circle() {
        let circles = workspace_circles(&workspace::root()).unwrap();
        let listed: String = circles.iter().map(|circle| circle.to_string()).collect();
        assert!(circles.is_empty(), "{listed}");
    }
}
