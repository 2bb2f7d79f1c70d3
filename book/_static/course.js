// The sidebar buttons readers see must work (issue 38).
//
// pydata-sphinx-theme 0.17.1, which sphinx-book-theme 1.3.0 pins, binds its sidebar drawers to the
// first `.primary-toggle` and `.secondary-toggle` of the page (pydata-sphinx-theme#2451), and
// sphinx-book-theme binds its "collapse the sidebar" to the first `.primary-toggle` too. Both are
// the hidden buttons of pydata-sphinx-theme's own header, since sphinx-book-theme shows its own
// buttons in the article's header: on a phone the chapter list could not be opened, and on a
// laptop the sidebar could not be collapsed. This file is deferred in the head, so it runs before
// both themes bind their buttons (pydata-sphinx-theme's script is deferred at the end of the body,
// sphinx-book-theme's waits for DOMContentLoaded): it takes the class off the hidden buttons.
for (const kind of ["primary-toggle", "secondary-toggle"]) {
  const buttons = document.querySelectorAll(`.${kind}`);
  if (buttons.length > 1) {
    for (const button of buttons) {
      if (button.closest("#pst-header")) button.classList.remove(kind);
    }
  }
}
