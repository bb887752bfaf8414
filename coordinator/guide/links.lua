-- links.lua -- pandoc filter for the user guide (guide.sh): links between
-- the documents point at their HTML pages, links to other files of the
-- repository at those files, and "franja(1)"-style names become links to
-- the manual pages.
--
-- Metadata (pandoc -M): guide_src, the source's path from the repository's
-- root; guide_map, "SRC=PAGE SRC=PAGE ..." for every document of the guide;
-- guide_root, the repository's root seen from the guide's directory;
-- guide_api, the API documentation's index seen from there.

local map, src, root, api = {}, "", "", ""

local function meta_string(v)
  return v and pandoc.utils.stringify(v) or ""
end

-- "a/b/../c" -> "a/c"; "./x" -> "x".
local function normalize(path)
  local out = {}
  for part in path:gmatch("[^/]+") do
    if part == ".." and #out > 0 and out[#out] ~= ".." then
      table.remove(out)
    elseif part ~= "." then
      table.insert(out, part)
    end
  end
  return table.concat(out, "/")
end

local function dirname(path)
  return path:match("^(.*)/[^/]*$") or ""
end

function Meta(m)
  src = meta_string(m.guide_src)
  root = meta_string(m.guide_root)
  api = meta_string(m.guide_api)
  for s, page in meta_string(m.guide_map):gmatch("(%S+)=(%S+)") do
    map[s] = page
  end
end

-- The page of a man page named NAME(SECTION), if the guide has one.
local function man_page(name, section)
  return map["coordinator/man/" .. name .. "." .. section]
end

-- A link's or an image's target as the guide's page sees it, or nil to
-- leave it (absolute URLs, fragments of the same page).
local function retarget(t)
  if t:match("^%a[%w+.-]*:") or t:match("^#") or t == "" then
    return nil
  end
  local path, frag = t:match("^([^#]*)(#?.*)$")
  local full = normalize((dirname(src) ~= "" and dirname(src) .. "/" or "") .. path)
  if map[full] then
    return map[full] .. frag
  elseif full:match("^build/docs/guide/") then
    return full:gsub("^build/docs/guide/", "") .. frag
  elseif full:match("^build/docs/html/") then
    return api:gsub("index%.html$", "") .. full:gsub("^build/docs/html/", "") .. frag
  end
  return root .. "/" .. full .. frag
end

function Link(el)
  local t = retarget(el.target)
  if t then
    el.target = t
    return el
  end
end

function Image(el)
  local t = retarget(el.src)
  if t then
    el.src = t
    return el
  end
end

-- franja(1), franja-worker(1), franja-hosts(5) in running text.
local function man_links(inlines)
  local out, changed = {}, false
  for _, el in ipairs(inlines) do
    local text = (el.t == "Str" or el.t == "Code") and el.text or nil
    local pre, name, sec, post
    if text then
      pre, name, sec, post = text:match("^(.-)(franja[%w-]*)%((%d)%)(.*)$")
    end
    local page = name and man_page(name, sec)
    if page then
      changed = true
      if pre ~= "" then table.insert(out, pandoc.Str(pre)) end
      local label = el.t == "Code" and pandoc.Code(name .. "(" .. sec .. ")") or pandoc.Str(name .. "(" .. sec .. ")")
      table.insert(out, pandoc.Link({label}, page))
      if post ~= "" then table.insert(out, pandoc.Str(post)) end
    else
      table.insert(out, el)
    end
  end
  return changed and out or nil
end

-- Only a paragraph's own words: names inside links and headings stay.
local function walk_block(b)
  local c = man_links(b.content)
  if c then
    b.content = c
    return b
  end
end

return {
  {Meta = Meta},
  {Link = Link, Image = Image},
  {Para = walk_block, Plain = walk_block},
}
