-- Neovim's own LSP client against `aviary lsp`, headless: run by tests/neovim.rs as
--   nvim --headless --clean -c "luafile lsp.lua" MISSION
-- with AVIARY_BIN (the binary) and AVIARY_NVIM_OUT (where to write what it saw, as JSON).
-- Works on Neovim 0.7 (Debian 12: no vim.lsp.start) and later.

local out = {}
local function finish()
  local f = io.open(os.getenv("AVIARY_NVIM_OUT"), "w")
  f:write(vim.fn.json_encode(out))
  f:close()
  vim.cmd("qa!")
end

local ok, err = pcall(function()
  local buf = vim.api.nvim_get_current_buf()
  local id = vim.lsp.start_client({
    name = "aviary",
    cmd = { os.getenv("AVIARY_BIN"), "lsp" },
    root_dir = vim.fn.expand("%:p:h"),
  })
  vim.lsp.buf_attach_client(buf, id)
  local client = vim.lsp.get_client_by_id(id)

  -- The position just inside the first `needle` of the buffer (ASCII lines: bytes are
  -- UTF-16 units).
  local function at(needle)
    for n, line in ipairs(vim.api.nvim_buf_get_lines(buf, 0, -1, false)) do
      local s = line:find(needle, 1, true)
      if s then
        return { line = n - 1, character = s }
      end
    end
    error("no " .. needle)
  end
  local function request(method, params)
    params.textDocument = { uri = vim.uri_from_bufnr(buf) }
    local answer = client.request_sync(method, params, 10000, buf)
    assert(answer and not answer.err, method .. ": " .. vim.inspect(answer))
    return answer.result
  end

  vim.wait(20000, function() return #vim.diagnostic.get(buf) > 0 end, 50)
  out.diagnostics = {}
  for _, d in ipairs(vim.diagnostic.get(buf)) do
    local lsp = d.user_data and d.user_data.lsp or {}
    table.insert(out.diagnostics, string.format("%d:%d %s %s", d.lnum + 1, d.col, d.code or lsp.code or "?", d.message))
  end

  local hover = request("textDocument/hover", { position = at("FlyCircle WITH") })
  out.hover = hover.contents.value

  local definition = request("textDocument/definition", { position = at("BuildingA") })
  out.definition = { uri = definition[1].uri, line = definition[1].range.start.line }

  -- Into the standard library: the file `aviary lsp` wrote it to, opened as Neovim
  -- opens any location, read-only.
  local std = request("textDocument/definition", { position = at("FlyCircle WITH") })
  if vim.lsp.util.show_document then
    vim.lsp.util.show_document(std[1], "utf-16", { focus = true })
  else
    vim.lsp.util.jump_to_location(std[1], "utf-16")
  end
  out.std = { name = vim.api.nvim_buf_get_name(0), line = vim.api.nvim_get_current_line() }
  vim.api.nvim_set_current_buf(buf)

  local completion = request("textDocument/completion", { position = { line = at("FlyCircle WITH").line, character = at("FlyCircle WITH").character + #"FlyCircle WITH" } })
  out.completion = {}
  for _, item in ipairs(completion.items or completion) do
    table.insert(out.completion, item.label)
  end

  local edit = request("textDocument/rename", { position = at("Video2_Ready"), newName = "Camera2_Ready" })
  vim.lsp.util.apply_workspace_edit(edit, "utf-16")

  local edits = request("textDocument/formatting", { options = { tabSize = 4, insertSpaces = true } })
  vim.lsp.util.apply_text_edits(edits, buf, "utf-16")
  out.text = table.concat(vim.api.nvim_buf_get_lines(buf, 0, -1, false), "\n") .. "\n"
end)
if not ok then
  out.error = tostring(err)
end
finish()
