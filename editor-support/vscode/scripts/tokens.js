// Prints the TextMate tokens of a file as JSON lines of {text, scopes}: what
// scripts/preview.py colours. Usage: node scripts/tokens.js FILE
const fs = require("fs");
const { loadGrammar, tokenize } = require("../test/tokenize");

loadGrammar().then((grammar) => {
    const text = fs.readFileSync(process.argv[2], "utf8");
    process.stdout.write(JSON.stringify(tokenize(grammar, text)));
});
