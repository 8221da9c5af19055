// The protocol's edges and the editor's lists: params the client got wrong, named by their
// field; every diagnostic up to a thousand; completion that offers only what can be
// written where the cursor is.
#include <doctest/doctest.h>

#include "lsp/positions.h"
#include "lsp/transport.h"
#include "lsp_support.h"

using namespace psys;
using namespace psys::lsp;
using namespace psys::lsp::test;
using nlohmann::json;

TEST_CASE("protocol: bad params are named by their field and what was expected, never in the JSON library's words") {
    Session s;
    s.request(1, "initialize");
    std::string uri = "file:///tmp/params.psys";
    s.server.handle({{"jsonrpc", "2.0"}, {"method", "textDocument/didOpen"},
                     {"params", {{"textDocument", {{"uri", uri}, {"text", kFireworks}, {"version", 1}}}}}});
    auto message = [&](int id, const std::string& method, json params) {
        json r = s.request(id, method, std::move(params));
        CHECK(r["error"]["code"] == error::kInvalidParams);
        std::string m = r["error"]["message"];
        CHECK(m.find("json.exception") == std::string::npos);
        return m;
    };
    json doc = {{"uri", uri}};
    CHECK(message(2, "textDocument/hover", {{"textDocument", doc}}) == "invalid params: `position` is missing");
    CHECK(message(3, "textDocument/hover", {{"textDocument", doc}, {"position", {{"line", "two"}, {"character", 0}}}}) ==
          "invalid params: `position.line` must be a count from 0, not \"two\"");
    CHECK(message(4, "textDocument/hover", {{"textDocument", 7}}) == "invalid params: `textDocument` must be an object, not 7");
    CHECK(message(5, "textDocument/hover", {{"textDocument", {{"uri", 3}}}}) ==
          "invalid params: `textDocument.uri` must be a string, not 3");
    CHECK(message(6, "textDocument/hover", json::array({1, 2})) == "invalid params: the params must be an object, not [1,2]");
    CHECK(message(7, "textDocument/rename", {{"textDocument", doc}, {"position", {{"line", 0}, {"character", 8}}}}) ==
          "invalid params: `newName` is missing");
    CHECK(message(8, "textDocument/codeAction",
                  {{"textDocument", doc},
                   {"range", {{"start", {{"line", 0}, {"character", 0}}}, {"end", {{"line", 0}, {"character", 0}}}}},
                   {"context", {{"diagnostics", {{{"range", {{"start", {{"line", 0}}}}}}}}}}}) ==
          "invalid params: `context.diagnostics[0].range.start.character` is missing");
    CHECK(message(9, "textDocument/references", {{"textDocument", doc}, {"position", {{"line", 0}, {"character", 8}}},
                                                 {"context", {{"includeDeclaration", "yes"}}}}) ==
          "invalid params: `context.includeDeclaration` must be true or false, not \"yes\"");
    // A long value is shortened in the message.
    std::string m = message(10, "textDocument/hover", {{"textDocument", {{"uri", json::array({std::string(500, 'x')})}}}});
    CHECK(m.size() < 120);
    // A change with a bad second part leaves the text as it was (the first is not applied).
    s.out.clear();
    s.server.handle({{"jsonrpc", "2.0"}, {"id", 11}, {"method", "textDocument/didChange"},
                     {"params", {{"textDocument", {{"uri", uri}, {"version", 2}}},
                                 {"contentChanges", {{{"text", "broken"}}, {{"text", 5}}}}}}});
    REQUIRE(s.out.size() == 1);
    CHECK(s.out[0]["error"]["message"] == "invalid params: `contentChanges[1].text` must be a string, not 5");
    json symbols = s.request(12, "textDocument/documentSymbol", {{"textDocument", doc}})["result"];
    CHECK(symbols.size() >= 3);  // fireworks' declarations, not the text "broken"
}

TEST_CASE("diagnostics: an editor gets every error up to a thousand, and a note that says how many more there are") {
    // 70 unknown names: past the terminal's 50, all published.
    std::string text;
    for (int i = 0; i < 70; ++i) text += "const c" + std::to_string(i) + " = nope" + std::to_string(i) + ";\n";
    Analysis a = analyze("/tmp/many.psys", text);
    auto byUri = diagnosticsByUri(a);
    REQUIRE(byUri.size() == 1);
    const json& list = byUri.begin()->second;
    CHECK(list.size() == 70);
    CHECK(list[69]["message"].get<std::string>().find("nope69") != std::string::npos);
    // 1,200: the first thousand, and a note at the top saying 200 more.
    text.clear();
    for (int i = 0; i < 1200; ++i) text += "const c" + std::to_string(i) + " = nope;\n";
    a = analyze("/tmp/many.psys", text);
    CHECK(a.hiddenErrors == 200);
    json cut = diagnosticsByUri(a).begin()->second;
    REQUIRE(cut.size() == kMaxPublished + 1);
    CHECK(cut.back()["message"] == "200 more errors and 0 more warnings are not listed (the first 1000 of each are)");
    CHECK(cut.back()["range"]["start"] == json{{"line", 0}, {"character", 0}});
}

TEST_CASE("completion: members only of an enclosing object, keywords only where they can be written") {
    // spark is declared at the top, not inside rocket: `rocket.` there offers nothing (the
    // checker refuses rocket.vel in spark), inside a child of rocket it offers rocket's members.
    std::string text = R"(object rocket(ivel: vec3) {
    vel = snapshot(ivel);
    pos = origin + integrate(vel);
    object ember { pos = rocket.pos; }
}
object spark(ipos: vec3) {
    pos = snapshot(ipos) + integrate(rocket.vel);
}
fn f(x: float) -> float = x;
spawn rocket(vec3(0, 1, 0));
)";
    Analysis a = analyze("/tmp/scope.psys", text);
    CHECK(labels(completion(a, text, at(text, "rocket.vel", 1, 7))).empty());
    CHECK(labels(completion(a, text, at(text, "rocket.pos", 1, 7))) == std::vector<std::string>{"alive", "age", "ivel", "vel", "pos"});
    auto inObject = labels(completion(a, text, at(text, "integrate(vel)")));
    for (const char* k : {"emit", "kill", "point", "object", "when", "if"}) CHECK_MESSAGE(has(inObject, k), k);
    for (const char* k : {"import", "fn", "const", "extern", "trigger", "spawn", "let"}) CHECK_MESSAGE(!has(inObject, k), k);
    auto inFn = labels(completion(a, text, at(text, "= x;", 1, 2)));
    CHECK(has(inFn, "let"));
    CHECK(has(inFn, "if"));
    for (const char* k : {"emit", "import", "object", "kill"}) CHECK_MESSAGE(!has(inFn, k), k);
    auto top = labels(completion(a, text, at(text, "spawn rocket")));
    for (const char* k : {"import", "fn", "object", "spawn", "extern"}) CHECK_MESSAGE(has(top, k), k);
}
