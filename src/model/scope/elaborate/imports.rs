//! `use`: modules and files loaded through the `Loader` (the standard library built in), each
//! once, import cycles reported; their names imported one by one or all. Contract: asks the
//! loader for texts and parses them; must not read files itself.

use super::*;

impl Elaborator<'_> {
    pub(super) fn import(&mut self, target: &UseTarget, span: Span, scope: ScopeId, file: &str) {
        let (module, item): (Vec<String>, Option<Ident>) = match target {
            UseTarget::File(path) => {
                let Some(ms) = self.load(
                    &format!("\"{path}\""),
                    LoadRequest::File { path, from: file },
                    span,
                    scope,
                ) else {
                    return;
                };
                return self.import_all(ms, scope, span);
            }
            UseTarget::Module(segs) => (segs.iter().map(|s| s.name.clone()).collect(), None),
        };
        // `use a::b::c`: module a::b::c entire, or item c of module a::b.
        let whole = module.join("::");
        if let Some(ms) = self.try_load(&module, span, scope, file) {
            return self.import_all(ms, scope, span);
        }
        let _ = item;
        if module.len() >= 2 {
            let (m, last) = module.split_at(module.len() - 1);
            if let Some(ms) = self.try_load(m, span, scope, file) {
                let name = &last[0];
                let Some(named) = self.env.scopes[ms].names.get(name).cloned() else {
                    let names: Vec<String> = self.env.scopes[ms].names.keys().cloned().collect();
                    let d = Diagnostic::error(
                        Code::E0216,
                        format!("module `{}` has no `{name}`", m.join("::")),
                    )
                    .at(span, "not found");
                    let hint = match did_you_mean(name, names.iter().map(|s| s.as_str())) {
                        Some(s) => format!("did you mean `{s}`?"),
                        None => format!("it declares: {}", names.join(", ")),
                    };
                    return self.error(scope, d.hint(hint));
                };
                let ident = Ident {
                    name: name.clone(),
                    span,
                };
                if let Err(d) = self.env.declare(scope, &ident, None, named) {
                    self.error(scope, d);
                }
                return;
            }
        }
        if !self.errors.iter().any(|e| e.code == Code::E0217) {
            let stdlib: Vec<&str> = crate::stdlib::MODULES.iter().map(|m| m.0).collect();
            self.error(
                scope,
                Diagnostic::error(Code::E0216, format!("cannot find module `{whole}`"))
                    .at(span, "not found")
                    .hint(format!(
                        "the standard library has: {}; your own modules are searched next to the model file and in the directories of MBD_PATH",
                        stdlib.iter().map(|m| format!("stdlib::{m}")).collect::<Vec<_>>().join(", ")
                    )),
            );
        }
    }

    fn import_all(&mut self, ms: ScopeId, scope: ScopeId, span: Span) {
        let mut names: Vec<(String, Named)> = self.env.scopes[ms]
            .names
            .iter()
            .filter(|(_, n)| matches!(n, Named::Component(..)))
            .map(|(k, n)| (k.clone(), n.clone()))
            .collect();
        names.sort_by(|a, b| a.0.cmp(&b.0));
        for (name, named) in names {
            let ident = Ident { name, span };
            if let Err(d) = self.env.declare(scope, &ident, None, named) {
                self.error(scope, d);
            }
        }
    }

    fn try_load(
        &mut self,
        module: &[String],
        span: Span,
        scope: ScopeId,
        file: &str,
    ) -> Option<ScopeId> {
        let key = module.join("::");
        if module.first().map(|s| s.as_str()) == Some("stdlib") {
            let name = module[1..].join("::");
            let text = crate::stdlib::MODULES.iter().find(|m| m.0 == name)?.1;
            return self.load_text(
                &key,
                &format!("stdlib/{name}.mbd"),
                text.to_string(),
                span,
                scope,
            );
        }
        self.load(
            &key,
            LoadRequest::Module {
                path: module,
                from: file,
            },
            span,
            scope,
        )
    }

    fn load(&mut self, key: &str, req: LoadRequest, span: Span, scope: ScopeId) -> Option<ScopeId> {
        if let Some(&s) = self.modules.get(key) {
            return Some(s);
        }
        if self.loading.iter().any(|k| k == key) {
            return self.cycle(key, span, scope);
        }
        match self.loader.load(&req) {
            Ok((name, text)) => self.load_text(key, &name, text, span, scope),
            Err(None) => None,
            Err(Some(msg)) => {
                self.error(
                    scope,
                    Diagnostic::error(Code::E0216, format!("cannot read `{key}`: {msg}"))
                        .at(span, "imported here")
                        .hint("check the path; relative paths start at the importing file's directory"),
                );
                None
            }
        }
    }

    fn cycle(&mut self, key: &str, span: Span, scope: ScopeId) -> Option<ScopeId> {
        let chain = self.loading.join(" -> ");
        self.error(
            scope,
            Diagnostic::error(Code::E0217, format!("import cycle: {chain} -> {key}"))
                .at(span, "imports a module that is still being loaded")
                .hint("move what both modules need into a third module that imports neither"),
        );
        None
    }

    fn load_text(
        &mut self,
        key: &str,
        name: &str,
        text: String,
        span: Span,
        scope: ScopeId,
    ) -> Option<ScopeId> {
        if let Some(&s) = self.modules.get(key) {
            return Some(s);
        }
        if self.loading.iter().any(|k| k == key) {
            return self.cycle(key, span, scope);
        }
        let id = self.sources.add(name, text.clone());
        let file = match crate::syntax::parse_file(&text, id) {
            Ok(f) => f,
            Err(d) => {
                self.errors.push(d);
                return None;
            }
        };
        self.loading.push(key.to_string());
        let ms = self.env.new_scope(None, String::new(), None);
        self.items(&file.items, ms, Where::Module, name);
        self.loading.pop();
        self.modules.insert(key.to_string(), ms);
        Some(ms)
    }
}
