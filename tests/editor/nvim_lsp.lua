-- Neovim (Debian's 0.7, headless) as the language server's client: its own LSP client
-- starts `psysc lsp` (vim.lsp.start_client, as editor-support/README.md sets it up for
-- 0.7), and each feature is asked for as a user's key would ask. Writes "ok <feature>"
-- per feature and "done" to $PSYS_NVIM_OUT; any failure ends with exit status 1.
local psysc = os.getenv("PSYSC")
local dir = os.getenv("PSYS_NVIM_DIR")
local out = assert(io.open(os.getenv("PSYS_NVIM_OUT"), "w"))

local function fail(what)
  out:write("FAIL " .. what .. "\n")
  out:close()
  vim.cmd("cquit 1")
end
local function ok(what) out:write("ok " .. what .. "\n") end
local function check(cond, what) if not cond then fail(what) end end

local text = {
  "extern sparks: float = 50;",
  "fn gravity(m: float) -> vec3 = vec3(0, -9.82 * m, 0);",
  "@integrator(rk4)",
  "object rocket(ivel: vec3) {",
  "    pos = origin + integrate(vel);",
  "    vel = snapshot(ivel) + integrate(gravity(0.3));",
  "    point(pos, white, 2);",
  "    kill when vel.y < 0;",
  "}",
  "spawn rocket(vec3(0, 15, 0));",
}
local file = dir .. "/fireworks.psys"
vim.fn.writefile(text, file)
-- In the workspace from the start, never opened until a rename edits it (the workspace index).
local bouncyFile, marblesFile = dir .. "/bouncy.psys", dir .. "/marbles.psys"
vim.fn.writefile({ "fn bounce(v: float) -> float = -v * 0.8;" }, bouncyFile)
vim.fn.writefile({ 'import "bouncy.psys";', "const k = bounce(1);" }, marblesFile)
vim.cmd("edit " .. file)
vim.bo.filetype = "psys"
local id = vim.lsp.start_client({ name = "psysc", cmd = { psysc, "lsp", "--debounce", "0" }, root_dir = dir })
check(id, "the client starts")
vim.lsp.buf_attach_client(0, id)
-- editor-support/neovim/inlay_hints.lua attached as the README says, before the server has
-- answered `initialize`: the hints show when the file opens, with no edit.
local inlay = dofile("editor-support/neovim/inlay_hints.lua")
inlay.attach(0, id)
check(vim.wait(10000, function()
  local c = vim.lsp.get_client_by_id(id)
  return c ~= nil and c.initialized
end, 20), "the server initialises")
ok("initialize")

-- One request at the cursor (row 1-based, column 0-based), its first result.
local function at(row, col, method, extra)
  vim.api.nvim_win_set_cursor(0, { row, col })
  local params = vim.lsp.util.make_position_params()
  for k, v in pairs(extra or {}) do params[k] = v end
  local answers = vim.lsp.buf_request_sync(0, method, params, 5000)
  check(answers ~= nil, method .. " answered")
  for _, a in pairs(answers) do
    check(a.error == nil, method .. ": " .. vim.inspect(a.error))
    return a.result
  end
end

local hover = at(6, 40, "textDocument/hover")
check(hover and hover.contents.value:find("fn gravity", 1, true), "hover on a function: " .. vim.inspect(hover))
local integrator = at(3, 13, "textDocument/hover")
check(integrator and integrator.contents.value:find("order 4", 1, true), "hover on an integrator")
ok("hover")

local def = at(5, 30, "textDocument/definition")
def = def[1] or def
check(def.range.start.line == 5 and def.range.start.character == 4, "definition: " .. vim.inspect(def))
ok("definition")

local refs = at(6, 4, "textDocument/references", { context = { includeDeclaration = true } })
check(#refs == 3, "references to vel: " .. vim.inspect(refs))
ok("references")

local hl = at(5, 4, "textDocument/documentHighlight")
check(#hl == 2 and hl[1].kind == 3, "highlights of pos: " .. vim.inspect(hl))
ok("documentHighlight")

local symbols = at(1, 0, "textDocument/documentSymbol")
local names = {}
for _, s in ipairs(symbols) do names[#names + 1] = s.name end
check(vim.tbl_contains(names, "rocket") and vim.tbl_contains(names, "gravity"), "symbols: " .. vim.inspect(names))
ok("documentSymbol")

local items = at(7, 4, "textDocument/completion")
items = items.items or items
local labels = {}
for _, i in ipairs(items) do labels[i.label] = true end
check(labels["vel"] and labels["sparks"], "completion inside rocket")
ok("completion")

-- Inlay hints (0.7 shows none itself: asked for as a request): vel's type, rocket's method.
vim.api.nvim_win_set_cursor(0, { 1, 0 })
local hints = vim.lsp.buf_request_sync(0, "textDocument/inlayHint", {
  textDocument = vim.lsp.util.make_text_document_params(),
  range = { start = { line = 0, character = 0 }, ["end"] = { line = 10, character = 0 } },
}, 5000)
local labels = {}
for _, a in pairs(hints) do for _, h in ipairs(a.result or {}) do labels[#labels + 1] = h.label end end
check(vim.tbl_contains(labels, ": vec3") and vim.tbl_contains(labels, "rk4, a step per update"),
  "inlay hints: " .. vim.inspect(labels))
ok("inlayHint")
local shown = {}
check(vim.wait(5000, function()
  shown = {}
  local ns = vim.api.nvim_create_namespace("psys_inlay_hints")
  for _, m in ipairs(vim.api.nvim_buf_get_extmarks(0, ns, 0, -1, { details = true })) do
    for _, chunk in ipairs(m[4].virt_text or {}) do shown[#shown + 1] = chunk[1] end
  end
  return #shown > 0
end, 20), "inlay_hints.lua shows hints on open, before any edit")
check(table.concat(shown, "|"):find("vel: vec3", 1, true), "inlay_hints.lua's text: " .. vim.inspect(shown))
ok("inlay_hints.lua on open")

local help = at(6, 46, "textDocument/signatureHelp")
check(help and help.signatures[1].label:find("fn gravity", 1, true) and help.activeParameter == 0, "signature help")
ok("signatureHelp")
local folds = vim.lsp.buf_request_sync(0, "textDocument/foldingRange", { textDocument = vim.lsp.util.make_text_document_params() }, 5000)
local rocketFold = false
for _, a in pairs(folds) do for _, f in ipairs(a.result or {}) do rocketFold = rocketFold or (f.startLine <= 3 and f.endLine == 8) end end
check(rocketFold, "the object folds: " .. vim.inspect(folds))
ok("foldingRange")
local ws = vim.lsp.buf_request_sync(0, "workspace/symbol", { query = "grav" }, 5000)
local found = false
for _, a in pairs(ws) do for _, s in ipairs(a.result or {}) do found = found or s.name == "gravity" end end
check(found, "workspace symbol")
ok("workspaceSymbol")

-- Semantic tokens (0.7 does not colour with them; a client that does asks so).
local sem = vim.lsp.buf_request_sync(0, "textDocument/semanticTokens/full",
  { textDocument = vim.lsp.util.make_text_document_params() }, 5000)
for _, a in pairs(sem) do
  check(a.result and #a.result.data >= 5 and #a.result.data % 5 == 0, "semantic tokens: " .. vim.inspect(a))
end
ok("semanticTokens")

-- Rename `vel` to `speed`: the edit applied to the buffer as the client applies it.
local edit = at(6, 4, "textDocument/rename", { newName = "speed" })
vim.lsp.util.apply_workspace_edit(edit, "utf-16")
local lines = vim.api.nvim_buf_get_lines(0, 0, -1, false)
check(lines[5] == "    pos = origin + integrate(speed);", "renamed: " .. lines[5])
check(lines[8] == "    kill when speed.y < 0;", "renamed: " .. lines[8])
local refused = vim.lsp.buf_request_sync(0, "textDocument/rename",
  vim.tbl_extend("force", vim.lsp.util.make_position_params(), { newName = "at" }), 5000)
for _, a in pairs(refused) do check(a.error and a.error.message:find("keyword", 1, true), "a keyword refused") end
ok("rename")

-- Diagnostics: a typo is published, as the client shows it.
vim.api.nvim_buf_set_lines(0, 6, 7, false, { "    point(pso, white, 2);" })
check(vim.wait(10000, function() return #vim.diagnostic.get(0) > 0 end, 20), "a diagnostic arrives")
local d = vim.diagnostic.get(0)[1]
check(d.lnum == 6 and d.message:find("pso", 1, true), "the diagnostic: " .. vim.inspect(d))
ok("diagnostics")

-- The quick fix of the typo's did-you-mean, chosen as a user picks it from the list.
vim.api.nvim_win_set_cursor(0, { 7, 10 })
local params = vim.lsp.util.make_range_params()
params.context = { diagnostics = vim.lsp.diagnostic.get_line_diagnostics() }
local actions = vim.lsp.buf_request_sync(0, "textDocument/codeAction", params, 5000)
local fix
for _, a in pairs(actions) do
  check(a.error == nil, "codeAction: " .. vim.inspect(a.error))
  fix = a.result and a.result[1]
end
check(fix and fix.title == "Change to `pos`" and fix.kind == "quickfix", "the quick fix: " .. vim.inspect(fix))
vim.lsp.util.apply_workspace_edit(fix.edit, "utf-16")
check(vim.api.nvim_buf_get_lines(0, 6, 7, false)[1] == "    point(pos, white, 2);", "the fix applied")
ok("codeAction")

-- Formatting (0.7's synchronous call): a line typed without spaces is laid out.
vim.api.nvim_buf_set_lines(0, 9, 10, false, { "spawn rocket(vec3(0,15,0)) ;" })
vim.lsp.buf.formatting_sync(nil, 5000)
local formatted = vim.api.nvim_buf_get_lines(0, 9, 10, false)[1]
check(formatted == "spawn rocket(vec3(0, 15, 0));", "formatted: " .. formatted)
ok("formatting")

-- Two files, neither saved after a rename across them: main.psys imports lib.psys and
-- calls its `lift`; renamed to `rise` from main (both buffers edited as the client applies
-- the edit), main is checked against lib's text in the editor, not the one on disk.
vim.o.hidden = true
local libFile, mainFile = dir .. "/lib.psys", dir .. "/main.psys"
vim.fn.writefile({ "fn lift(h: float) -> vec3 = vec3(0, h, 0);" }, libFile)
vim.fn.writefile({ 'import "lib.psys";', "object o {", "    pos = origin + lift(2);", "    point(pos, white, 1);",
  "    kill when age > 1;", "}", "spawn o;" }, mainFile)
vim.cmd("edit " .. libFile)
local libBuf = vim.api.nvim_get_current_buf()
vim.bo.filetype = "psys"
vim.lsp.buf_attach_client(0, id)
vim.cmd("edit " .. mainFile)
local mainBuf = vim.api.nvim_get_current_buf()
vim.bo.filetype = "psys"
vim.lsp.buf_attach_client(0, id)
local before = at(3, 20, "textDocument/hover")
check(before and before.contents.value:find("fn lift", 1, true), "hover before the rename: " .. vim.inspect(before))
local across = at(3, 20, "textDocument/rename", { newName = "rise" })
vim.lsp.util.apply_workspace_edit(across, "utf-16")
check(vim.api.nvim_buf_get_lines(libBuf, 0, 1, false)[1] == "fn rise(h: float) -> vec3 = vec3(0, h, 0);", "lib renamed")
check(vim.api.nvim_buf_get_lines(mainBuf, 2, 3, false)[1] == "    pos = origin + rise(2);", "main renamed")
check(vim.bo[libBuf].modified and vim.bo[mainBuf].modified, "neither saved")
-- (the client sends its changes after a pause: asked until they have come)
local riseHover
vim.wait(5000, function()
  riseHover = at(3, 20, "textDocument/hover")
  return riseHover and riseHover.contents.value:find("fn rise", 1, true)
end, 50)
check(riseHover and riseHover.contents.value:find("fn rise", 1, true), "hover on the renamed call: " .. vim.inspect(riseHover))
local riseDef = at(3, 20, "textDocument/definition")
riseDef = riseDef[1] or riseDef
check(riseDef.uri == vim.uri_from_fname(libFile) and riseDef.range.start.line == 0, "definition in lib: " .. vim.inspect(riseDef))
check(vim.wait(5000, function() return #vim.diagnostic.get(mainBuf) == 0 end, 20),
  "main's diagnostics: " .. vim.inspect(vim.diagnostic.get(mainBuf)))
ok("unsaved imports")

-- The workspace index: references to bounce from bouncy.psys find marbles.psys, which no
-- one opened, and a rename edits it.
vim.cmd("edit " .. bouncyFile)
vim.bo.filetype = "psys"
vim.lsp.buf_attach_client(0, id)
local uses = at(1, 4, "textDocument/references", { context = { includeDeclaration = true } })
local inMarbles = false
for _, r in ipairs(uses or {}) do inMarbles = inMarbles or r.uri == vim.uri_from_fname(marblesFile) end
check(#uses == 2 and inMarbles, "references across the workspace: " .. vim.inspect(uses))
check(vim.fn.bufloaded(marblesFile) == 0, "marbles.psys not opened")
local wide = at(1, 4, "textDocument/rename", { newName = "rebound" })
vim.lsp.util.apply_workspace_edit(wide, "utf-16")
local marblesBuf = vim.fn.bufnr(marblesFile)
check(marblesBuf > 0 and vim.api.nvim_buf_get_lines(marblesBuf, 1, 2, false)[1] == "const k = rebound(1);",
  "marbles.psys renamed: " .. vim.inspect(marblesBuf > 0 and vim.api.nvim_buf_get_lines(marblesBuf, 0, -1, false)))
ok("workspace index")

-- A file opened with a syntax error in it: the outline and hover answer outside the
-- broken declaration.
local brokenFile = dir .. "/broken.psys"
vim.fn.writefile({ "fn up(h: float) -> vec3 = vec3(0, h, 0);", "object o {", "    pos = origin + up(", "}",
  "object p {", "    pos = origin + up(1);", "    point(pos, white, 1);", "}", "spawn p;" }, brokenFile)
vim.cmd("edit " .. brokenFile)
vim.bo.filetype = "psys"
vim.lsp.buf_attach_client(0, id)
local outline = at(1, 0, "textDocument/documentSymbol")
local shown = {}
for _, sym in ipairs(outline or {}) do shown[#shown + 1] = sym.name end
check(vim.tbl_contains(shown, "up") and vim.tbl_contains(shown, "p") and not vim.tbl_contains(shown, "o"),
  "outline of a file opened broken: " .. vim.inspect(shown))
local upHover = at(6, 20, "textDocument/hover")
check(upHover and upHover.contents.value:find("fn up", 1, true), "hover in a file opened broken: " .. vim.inspect(upHover))
ok("opened with a syntax error")

out:write("done\n")
out:close()
vim.lsp.stop_client(id)
vim.cmd("qa!")
