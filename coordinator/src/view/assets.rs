//! The page's files, built into the binary: the view needs nothing installed and nothing from
//! the internet.

/// One file of the page.
#[derive(Debug, PartialEq)]
pub(super) struct Asset {
    /// The paths it is served at.
    pub paths: &'static [&'static str],
    /// Its `Content-Type`.
    pub content_type: &'static str,
    /// Its bytes.
    pub body: &'static [u8],
}

/// Every file the server answers.
static ASSETS: [Asset; 3] = [
    Asset {
        paths: &["/", "/index.html"],
        content_type: "text/html; charset=utf-8",
        body: include_bytes!("assets/index.html"),
    },
    Asset {
        paths: &["/view.js"],
        content_type: "text/javascript; charset=utf-8",
        body: include_bytes!("assets/view.js"),
    },
    Asset {
        paths: &["/view.css"],
        content_type: "text/css; charset=utf-8",
        body: include_bytes!("assets/view.css"),
    },
];

/// The file served at `path`.
pub(super) fn find(path: &str) -> Option<&'static Asset> {
    ASSETS.iter().find(|a| a.paths.contains(&path))
}
