//! A parser of the subset of RAPID a job's module holds: one `MODULE` of `PERS` and `CONST`
//! declarations (`tooldata`, `wobjdata`, `zonedata`) and a `PROC main()` of instructions, each
//! an identifier with its arguments (values: numbers, booleans, strings, identifiers and
//! aggregates `[...]`; optional arguments `\Name` and `\Name:=value`) up to its `;`. Comments run
//! from `!` to the end of the line. Anything else is refused naming its line.

use emg_program_check::{ReadError, fail};

/// A RAPID value.
#[derive(Clone, Debug, PartialEq)]
pub enum Value {
    /// A number.
    Number(f64),
    /// `TRUE` or `FALSE`.
    Bool(bool),
    /// A string literal.
    Text(String),
    /// An identifier (a data object's or a predefined one's name).
    Name(String),
    /// `[a, b, ...]`.
    Aggregate(Vec<Value>),
}

impl Value {
    /// The number this value is, else why not (naming `what`).
    pub fn number(&self, what: &str, line: usize) -> Result<f64, ReadError> {
        match self {
            Self::Number(n) => Ok(*n),
            other => fail(line, format!("{what} is {other:?}, not a number")),
        }
    }

    /// The `N` numbers of this aggregate, else why not.
    pub fn numbers<const N: usize>(&self, what: &str, line: usize) -> Result<[f64; N], ReadError> {
        let Self::Aggregate(items) = self else {
            return fail(line, format!("{what} is {self:?}, not an aggregate"));
        };
        if items.len() != N {
            return fail(
                line,
                format!("{what} holds {} values, not {N}", items.len()),
            );
        }
        let mut out = [0.0; N];
        for (slot, item) in out.iter_mut().zip(items) {
            *slot = item.number(what, line)?;
        }
        Ok(out)
    }

    /// The items of this aggregate, `count` of them, else why not.
    pub fn items(&self, what: &str, count: usize, line: usize) -> Result<&[Value], ReadError> {
        match self {
            Self::Aggregate(items) if items.len() == count => Ok(items),
            other => fail(
                line,
                format!("{what} is {other:?}, not an aggregate of {count} values"),
            ),
        }
    }
}

/// One argument of an instruction.
#[derive(Clone, Debug, PartialEq)]
pub enum Argument {
    /// A plain argument.
    Value(Value),
    /// `\Name` or `\Name:=value`.
    Switch(String, Option<Value>),
}

/// A declaration: `PERS|CONST|VAR type name := value;`.
#[derive(Clone, Debug, PartialEq)]
pub struct Declaration {
    /// Its line.
    pub line: usize,
    /// Its data type (`tooldata`, ...).
    pub data_type: String,
    /// Its name.
    pub name: String,
    /// Its value.
    pub value: Value,
}

/// An instruction of `main`.
#[derive(Clone, Debug, PartialEq)]
pub struct Instruction {
    /// Its line.
    pub line: usize,
    /// Its name (`MoveL`, ...).
    pub name: String,
    /// Its arguments, in order.
    pub arguments: Vec<Argument>,
}

impl Instruction {
    /// The plain arguments, in order.
    pub fn values(&self) -> Vec<&Value> {
        self.arguments
            .iter()
            .filter_map(|a| match a {
                Argument::Value(v) => Some(v),
                Argument::Switch(..) => None,
            })
            .collect()
    }

    /// The optional argument `\name`, if given (with its value, if any).
    pub fn switch(&self, name: &str) -> Option<Option<&Value>> {
        self.arguments.iter().find_map(|a| match a {
            Argument::Switch(n, v) if n == name => Some(v.as_ref()),
            _ => None,
        })
    }
}

/// A module: its declarations and `main`'s instructions.
#[derive(Clone, Debug, PartialEq)]
pub struct Module {
    /// The module's name.
    pub name: String,
    /// Its declarations.
    pub declarations: Vec<Declaration>,
    /// `main`'s instructions.
    pub main: Vec<Instruction>,
}

#[derive(Clone, Debug, PartialEq)]
enum Token {
    Word(String),
    Number(f64),
    Text(String),
    Open,
    Close,
    Comma,
    End,
    Backslash,
    Assign,
    LeftParen,
    RightParen,
}

/// The tokens of `text`, each with its line (from 1).
fn tokens(text: &str) -> Result<Vec<(Token, usize)>, ReadError> {
    let mut out = Vec::new();
    for (index, raw) in text.lines().enumerate() {
        let line = index + 1;
        let code = raw.split('!').next().unwrap_or("");
        let chars: Vec<char> = code.chars().collect();
        let mut i = 0;
        while i < chars.len() {
            let c = chars[i];
            let single = match c {
                '[' => Some(Token::Open),
                ']' => Some(Token::Close),
                ',' => Some(Token::Comma),
                ';' => Some(Token::End),
                '\\' => Some(Token::Backslash),
                '(' => Some(Token::LeftParen),
                ')' => Some(Token::RightParen),
                _ => None,
            };
            if let Some(token) = single {
                out.push((token, line));
                i += 1;
            } else if c.is_whitespace() {
                i += 1;
            } else if c == ':' && chars.get(i + 1) == Some(&'=') {
                out.push((Token::Assign, line));
                i += 2;
            } else if c == '"' {
                let end = chars[i + 1..]
                    .iter()
                    .position(|&d| d == '"')
                    .ok_or_else(|| ReadError::at(line, "a string without its closing quote"))?;
                out.push((
                    Token::Text(chars[i + 1..i + 1 + end].iter().collect()),
                    line,
                ));
                i += end + 2;
            } else if c.is_ascii_digit() || c == '-' || c == '+' || c == '.' {
                let start = i;
                i += 1;
                while i < chars.len()
                    && (chars[i].is_ascii_alphanumeric()
                        || chars[i] == '.'
                        || ((chars[i] == '-' || chars[i] == '+')
                            && matches!(chars[i - 1], 'e' | 'E')))
                {
                    i += 1;
                }
                let word: String = chars[start..i].iter().collect();
                let number = word
                    .parse::<f64>()
                    .map_err(|_| ReadError::at(line, format!("'{word}' is not a number")))?;
                out.push((Token::Number(number), line));
            } else if c.is_ascii_alphabetic() || c == '_' {
                let start = i;
                while i < chars.len() && (chars[i].is_ascii_alphanumeric() || chars[i] == '_') {
                    i += 1;
                }
                out.push((Token::Word(chars[start..i].iter().collect()), line));
            } else {
                return fail(line, format!("unexpected character '{c}'"));
            }
        }
    }
    Ok(out)
}

/// The tokens being parsed.
struct Cursor {
    tokens: Vec<(Token, usize)>,
    at: usize,
}

impl Cursor {
    fn line(&self) -> usize {
        self.tokens
            .get(self.at)
            .or(self.tokens.last())
            .map_or(0, |t| t.1)
    }

    fn peek(&self) -> Option<&Token> {
        self.tokens.get(self.at).map(|t| &t.0)
    }

    fn next(&mut self) -> Result<Token, ReadError> {
        let token = self
            .tokens
            .get(self.at)
            .cloned()
            .ok_or_else(|| ReadError::at(self.line(), "the module ends early"))?;
        self.at += 1;
        Ok(token.0)
    }

    fn expect(&mut self, token: &Token, what: &str) -> Result<(), ReadError> {
        let line = self.line();
        match self.next()? {
            found if &found == token => Ok(()),
            found => fail(line, format!("expected {what}, found {found:?}")),
        }
    }

    fn word(&mut self, what: &str) -> Result<String, ReadError> {
        let line = self.line();
        match self.next()? {
            Token::Word(w) => Ok(w),
            found => fail(line, format!("expected {what}, found {found:?}")),
        }
    }

    fn value(&mut self) -> Result<Value, ReadError> {
        let line = self.line();
        match self.next()? {
            Token::Number(n) => Ok(Value::Number(n)),
            Token::Text(t) => Ok(Value::Text(t)),
            Token::Word(w) if w.eq_ignore_ascii_case("TRUE") => Ok(Value::Bool(true)),
            Token::Word(w) if w.eq_ignore_ascii_case("FALSE") => Ok(Value::Bool(false)),
            Token::Word(w) => Ok(Value::Name(w)),
            Token::Open => {
                let mut items = Vec::new();
                loop {
                    items.push(self.value()?);
                    match self.next()? {
                        Token::Comma => continue,
                        Token::Close => break,
                        found => return fail(line, format!("expected , or ], found {found:?}")),
                    }
                }
                Ok(Value::Aggregate(items))
            }
            found => fail(line, format!("expected a value, found {found:?}")),
        }
    }
}

/// Parses a module.
pub fn parse_module(text: &str) -> Result<Module, ReadError> {
    let mut cursor = Cursor {
        tokens: tokens(text)?,
        at: 0,
    };
    let module = cursor.word("MODULE")?;
    if module != "MODULE" {
        return fail(cursor.line(), "the file does not start with MODULE");
    }
    let name = cursor.word("the module's name")?;
    let mut declarations = Vec::new();
    loop {
        let line = cursor.line();
        let word = cursor.word("a declaration or PROC")?;
        match word.as_str() {
            "PERS" | "CONST" | "VAR" => {
                let data_type = cursor.word("a data type")?;
                let name = cursor.word("a name")?;
                cursor.expect(&Token::Assign, ":=")?;
                let value = cursor.value()?;
                cursor.expect(&Token::End, ";")?;
                declarations.push(Declaration {
                    line,
                    data_type,
                    name,
                    value,
                });
            }
            "PROC" => break,
            other => return fail(line, format!("unexpected '{other}' among the declarations")),
        }
    }
    let proc_name = cursor.word("the routine's name")?;
    if proc_name != "main" {
        return fail(
            cursor.line(),
            format!("the routine is {proc_name}, not main"),
        );
    }
    cursor.expect(&Token::LeftParen, "(")?;
    cursor.expect(&Token::RightParen, ")")?;
    let mut main = Vec::new();
    loop {
        let line = cursor.line();
        let name = cursor.word("an instruction or ENDPROC")?;
        if name == "ENDPROC" {
            break;
        }
        let mut arguments = Vec::new();
        loop {
            match cursor.peek() {
                Some(Token::End) => {
                    cursor.next()?;
                    break;
                }
                Some(Token::Comma) => {
                    cursor.next()?;
                }
                Some(Token::Backslash) => {
                    cursor.next()?;
                    let switch = cursor.word("an optional argument's name")?;
                    let value = if cursor.peek() == Some(&Token::Assign) {
                        cursor.next()?;
                        Some(cursor.value()?)
                    } else {
                        None
                    };
                    arguments.push(Argument::Switch(switch, value));
                }
                Some(_) => arguments.push(Argument::Value(cursor.value()?)),
                None => return fail(line, format!("{name} without its ;")),
            }
        }
        main.push(Instruction {
            line,
            name,
            arguments,
        });
    }
    let line = cursor.line();
    if cursor.word("ENDMODULE")? != "ENDMODULE" || cursor.peek().is_some() {
        return fail(line, "the module does not end with ENDMODULE after main");
    }
    Ok(Module {
        name,
        declarations,
        main,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_module_parses_into_its_declarations_and_instructions() {
        let text = "MODULE M\n  ! a comment\n  PERS tooldata t := [TRUE, [[0, 0, 100], [1, 0, 0, \
                    0]], [0.1, [0, 0, 1], [1, 0, 0, 0], 0, 0, 0]];\n  CONST zonedata z := \
                    [FALSE, 0.5, 0.5, 0.5, 0.05, 0.5, 0.05];\n\n  PROC main()\n    ConfL \\On;\n    \
                    MoveL [[1.5, -2, 3E2], [1, 0, 0, 0], [0, -1, 2, 5], [9E9, 9E9, 9E9, 9E9, 9E9, \
                    9E9]], [200, 500, 5000, 1000], z, t \\WObj:=w;\n    SetDO do1, 1; ! on\n  \
                    ENDPROC\nENDMODULE\n";
        let module = parse_module(text).unwrap();
        assert_eq!(module.name, "M");
        assert_eq!(module.declarations.len(), 2);
        assert_eq!(module.declarations[1].line, 4);
        assert_eq!(module.main.len(), 3);
        let move_l = &module.main[1];
        assert_eq!((move_l.name.as_str(), move_l.line), ("MoveL", 8));
        assert_eq!(move_l.values().len(), 4);
        assert_eq!(
            move_l.switch("WObj"),
            Some(Some(&Value::Name("w".to_string())))
        );
        let target = move_l.values()[0].items("target", 4, 7).unwrap();
        assert_eq!(
            target[0].numbers::<3>("position", 7).unwrap(),
            [1.5, -2.0, 300.0]
        );
        assert_eq!(module.main[0].switch("On"), Some(None));
    }

    #[test]
    fn a_malformed_module_is_refused_at_its_line() {
        for (text, line) in [
            (
                "MODULE M\n  PROC main()\n    MoveL [1, 2;\n  ENDPROC\nENDMODULE\n",
                3,
            ),
            (
                "MODULE M\n  PROC main()\n    WaitTime 1\n  ENDPROC\nENDMODULE\n",
                3,
            ),
            ("MODULE M\n  FOO x;\n", 2),
            ("MODULE M\n  PROC main()\n    SetDO d, 1; @\n", 3),
        ] {
            let error = parse_module(text).unwrap_err();
            assert_eq!(error.line, line, "{text}: {error}");
        }
    }
}
