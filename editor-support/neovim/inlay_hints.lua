-- Inlay hints for Neovim before 0.10 (which shows them itself: vim.lsp.inlay_hint.enable()):
-- asks the server for the buffer's hints once it has opened the buffer, and after each
-- change, and shows them at the end of their lines. In init.lua: require("psys_inlay_hints").attach(bufnr, client_id), with this
-- file on the runtimepath as lua/psys_inlay_hints.lua (editor-support/README.md).
local M = {}
local ns = vim.api.nvim_create_namespace("psys_inlay_hints")

-- Whether the client has told the server the buffer is open: until then a request about it
-- is refused (the client sends `didOpen` once the server has answered `initialize`, which
-- is after a FileType callback has attached the buffer and called attach()).
local function opened(client, bufnr)
  return client.initialized and client.attached_buffers and client.attached_buffers[bufnr]
end

function M.refresh(bufnr, client_id, tries)
  local client = vim.lsp.get_client_by_id(client_id)
  if not client or not vim.api.nvim_buf_is_valid(bufnr) then return end
  if not opened(client, bufnr) then
    -- Asked again every 20 ms for as long as ten seconds (a server's start).
    tries = (tries or 0) + 1
    if tries <= 500 then vim.defer_fn(function() M.refresh(bufnr, client_id, tries) end, 20) end
    return
  end
  local last = vim.api.nvim_buf_line_count(bufnr)
  local params = {
    textDocument = { uri = vim.uri_from_bufnr(bufnr) },
    range = { start = { line = 0, character = 0 }, ["end"] = { line = last, character = 0 } },
  }
  client.request("textDocument/inlayHint", params, function(err, hints)
    if err or not vim.api.nvim_buf_is_valid(bufnr) then return end
    vim.api.nvim_buf_clear_namespace(bufnr, ns, 0, -1)
    local byLine = {}
    for _, h in ipairs(hints or {}) do
      local label = type(h.label) == "string" and h.label or h.label[1].value
      local row = h.position.line
      local word = vim.api.nvim_buf_get_lines(bufnr, row, row + 1, false)[1] or ""
      -- `pos: vec3` for a type after its name, the hint alone for the rest.
      local name = word:sub(1, h.position.character):match("([%w_]+)$")
      byLine[row] = byLine[row] or {}
      table.insert(byLine[row], (h.kind == 1 and name) and (name .. label) or label)
    end
    for row, labels in pairs(byLine) do
      vim.api.nvim_buf_set_extmark(bufnr, ns, row, 0,
        { virt_text = { { "  " .. table.concat(labels, "  "), "Comment" } }, virt_text_pos = "eol" })
    end
  end, bufnr)
end

function M.attach(bufnr, client_id)
  if bufnr == 0 then bufnr = vim.api.nvim_get_current_buf() end  -- (the client keys buffers by number)
  M.refresh(bufnr, client_id)
  vim.api.nvim_create_autocmd({ "InsertLeave", "TextChanged", "BufWritePost" }, {
    buffer = bufnr,
    callback = function() M.refresh(bufnr, client_id) end,
  })
end

return M
