// Turns the parser's error events into worded diagnostics.
//
// ANTLR reports "mismatched input 'x' expecting {';', '+', …}"; a user wants
// "expected ';' at end of equation, found 'point'". This error strategy keeps ANTLR's
// recovery (single-token insertion and deletion, then re-synchronisation) but words
// every report itself: what was expected in words, what was found, and where.
#pragma once

#include <antlr4-runtime.h>

#include "frontend/diagnostics.h"

namespace psys {

class SyntaxErrorReporter : public antlr4::DefaultErrorStrategy {
public:
    // `byteOffset` maps a character index of the input stream to a byte offset in the file.
    SyntaxErrorReporter(DiagnosticEngine& diags, int file, std::vector<uint32_t> byteOffset)
        : diags_(diags), file_(file), byteOffset_(std::move(byteOffset)) {}

protected:
    void reportNoViableAlternative(antlr4::Parser* parser, const antlr4::NoViableAltException& e) override;
    void reportInputMismatch(antlr4::Parser* parser, const antlr4::InputMismatchException& e) override;
    void reportFailedPredicate(antlr4::Parser* parser, const antlr4::FailedPredicateException& e) override;
    void reportUnwantedToken(antlr4::Parser* parser) override;
    bool keywordTakenForName(antlr4::Parser* parser, antlr4::Token* found);
    void reportMissingToken(antlr4::Parser* parser) override;
    // Never skips a ';' or '}' to go on with the current rule: they end statements, and
    // skipping one glues two statements together and turns one error into several.
    antlr4::Token* singleTokenDeletion(antlr4::Parser* parser) override;

private:
    void report(antlr4::Parser* parser, antlr4::Token* found, const antlr4::misc::IntervalSet& expected);
    SourceRange tokenRange(antlr4::Token* token) const;
    SourceRange afterPrevious(antlr4::Parser* parser) const;

    DiagnosticEngine& diags_;
    int file_;
    std::vector<uint32_t> byteOffset_;
};

}  // namespace psys
