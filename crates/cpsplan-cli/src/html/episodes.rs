//! The episode player of an experiment's page (`cpsplan report`): the pages of
//! chosen episodes (`experiment --html`) inside the one file, one shown at a
//! time in a frame, chosen from a list. The frame's page is the player of
//! `explore --html`, built in the browser from the shared player and the
//! episode's data; `#episode=K` (and `&step=N`) in the address picks one.

use anyhow::Result;

use super::{escape, player_template_json};

/// One episode the page can show.
#[derive(Debug, Clone)]
pub struct ShownEpisode {
    /// What the list calls it.
    pub label: String,
    /// The title of its page.
    pub title: String,
    /// Its page's data ([`super::page_data`]: JSON with no `<` in it).
    pub data: String,
}

/// The script that fills the frame.
const SCRIPT: &str = r#"<script>
"use strict";
(() => {
  const tpl = JSON.parse(document.getElementById("player-template").textContent);
  const pick = document.getElementById("episode"), frame = document.getElementById("player");
  const save = document.getElementById("save");
  const esc = (t) => t.replace(/&/g, "&amp;").replace(/</g, "&lt;").replace(/>/g, "&gt;").replace(/"/g, "&quot;");
  let wanted = null, timer = null;
  function page(k) {
    const o = pick.options[k], data = document.getElementById("ep-" + o.value).textContent;
    return tpl.replace(/__TITLE__|__DATA__/g, (m) => (m === "__TITLE__" ? esc(o.dataset.title) : data));
  }
  // Mirrors the frame's state on this page's body (for a reader and for tests).
  function watch() {
    clearInterval(timer);
    document.body.dataset.playerReady = "0";
    timer = setInterval(() => {
      const d = frame.contentDocument;
      if (!d || !d.body || d.body.dataset.ready !== "1") return;
      if (wanted !== null && frame.contentWindow.go) { frame.contentWindow.go(wanted); wanted = null; }
      document.body.dataset.playerTitle = d.getElementById("title").textContent;
      document.body.dataset.playerStep = d.getElementById("stepLabel").textContent;
      document.body.dataset.playerReady = "1";
    }, 100);
  }
  function show() {
    const html = page(pick.selectedIndex);
    frame.srcdoc = html;
    if (save.href) URL.revokeObjectURL(save.href);
    save.href = URL.createObjectURL(new Blob([html], { type: "text/html" }));
    save.download = "episode-" + pick.value + ".html";
    watch();
  }
  const m = /episode=(\d+)/.exec(location.hash), s = /step=(\d+)/.exec(location.hash);
  if (m) { const k = [...pick.options].findIndex((o) => o.value === m[1]); if (k >= 0) pick.selectedIndex = k; }
  if (s) wanted = Number(s[1]);
  pick.addEventListener("change", show);
  show();
})();
</script>
"#;

/// The player's section of the page: a list of `episodes` and a frame; `note`
/// says which episodes these are. Empty for no episodes.
pub fn player_section(episodes: &[(usize, ShownEpisode)], note: &str) -> Result<String> {
    if episodes.is_empty() {
        return Ok(String::new());
    }
    let mut out = format!(
        "<h2>Episodes</h2>\n<p>{}</p>\n<p><label>Episode <select id=\"episode\">",
        escape(note)
    );
    for (index, e) in episodes {
        out.push_str(&format!(
            "<option value=\"{index}\" data-title=\"{}\">{}</option>",
            escape(&e.title),
            escape(&e.label)
        ));
    }
    out.push_str(
        "</select></label> <a id=\"save\">save this episode's page</a></p>\n\
         <iframe id=\"player\" title=\"the chosen episode, scan by scan\" \
         style=\"width:100%;height:92vh;min-height:720px;border:1px solid #d9e2ec;border-radius:6px\"></iframe>\n",
    );
    out.push_str(&format!(
        "<script type=\"application/json\" id=\"player-template\">{}</script>\n",
        player_template_json()?
    ));
    for (index, e) in episodes {
        // The data hold no `<` (they end at the first), so nothing in them
        // ends the element; the replacement only makes sure.
        out.push_str(&format!(
            "<script type=\"application/json\" id=\"ep-{index}\">{}</script>\n",
            e.data.replace('<', "\\u003c")
        ));
    }
    out.push_str(SCRIPT);
    Ok(out)
}
