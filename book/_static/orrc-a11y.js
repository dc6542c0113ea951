// Wide blocks scroll in their own box with a visible cue (tools/sphinx_a11y.py): every display
// equation, code block and table wider than its box gets the class orrc-overflows (a scroll bar
// and a shadow on the side where more content waits), tabindex=0 and a region label, so that a
// keyboard can scroll it too. Re-checked when the window is resized and after MathJax typesets.
(function () {
  var SELECTOR = 'div.math, mjx-container[display="true"], div.highlight pre, .cell_output pre, ' +
                 'div.pst-scrollable-table-container, .table-wrapper, div.orrc-table-wrap, mjx-container.orrc-wide-inline, ' +
                 'div.orrc-map-wrap';
  function label(el) {
    if (el.matches('div.math, mjx-container')) { return 'equation, scrolls sideways'; }
    if (el.matches('pre')) { return 'code, scrolls sideways'; }
    if (el.matches('div.orrc-map-wrap')) { return 'map of the results, scrolls sideways'; }
    return 'table, scrolls sideways';
  }
  function edges(el) {
    el.classList.toggle('orrc-more-left', el.scrollLeft > 1);
    el.classList.toggle('orrc-more-right', el.scrollLeft + el.clientWidth < el.scrollWidth - 1);
  }
  // inline math wider than its paragraph (a long formula at a phone's width) becomes a small
  // scrolling box of its own instead of running past the column's edge
  function wideInline() {
    document.querySelectorAll('mjx-container:not([display="true"])').forEach(function (el) {
      el.classList.remove('orrc-wide-inline');
      var block = el.parentElement;
      while (block && getComputedStyle(block).display.indexOf('inline') === 0) { block = block.parentElement; }
      if (block && el.getBoundingClientRect().width > block.clientWidth + 1) { el.classList.add('orrc-wide-inline'); }
    });
  }
  function mark() {
    wideInline();
    document.querySelectorAll(SELECTOR).forEach(function (el) {
      var over = el.scrollWidth > el.clientWidth + 1;
      el.classList.toggle('orrc-overflows', over);
      if (over) {
        if (!(el.tabIndex >= 0 && el.hasAttribute('tabindex'))) {   // the theme may have set -1
          el.dataset.orrcTab = el.getAttribute('tabindex') === null ? 'none' : el.getAttribute('tabindex');
          el.setAttribute('tabindex', '0');
        }
        if (!el.hasAttribute('role')) { el.setAttribute('role', 'region'); el.dataset.orrcRole = '1'; }
        if (!el.hasAttribute('aria-label')) { el.setAttribute('aria-label', label(el)); el.dataset.orrcLabel = '1'; }
        if (!el.dataset.orrcScroll) {
          el.dataset.orrcScroll = '1';
          el.addEventListener('scroll', function () { edges(el); }, {passive: true});
        }
        edges(el);
      } else {
        if (el.dataset.orrcTab) {
          if (el.dataset.orrcTab === 'none') { el.removeAttribute('tabindex'); } else { el.setAttribute('tabindex', el.dataset.orrcTab); }
          delete el.dataset.orrcTab;
        }
        if (el.dataset.orrcRole) { el.removeAttribute('role'); delete el.dataset.orrcRole; }
        if (el.dataset.orrcLabel) { el.removeAttribute('aria-label'); delete el.dataset.orrcLabel; }
        el.classList.remove('orrc-more-left', 'orrc-more-right');
      }
    });
  }
  // names that match what a reader sees (WCAG 2.5.3, "label in name"; the axe-core audit): a button
  // or summary whose visible text is not in its aria-label takes its name from that text; icons
  // inside a labelled button are hidden from the name; the sidebar's section toggles get a name
  function names() {
    document.querySelectorAll('button[aria-label], summary[aria-label]').forEach(function (el) {
      var text = (el.innerText || '').replace(/\s+/g, ' ').trim().toLowerCase();
      var label = el.getAttribute('aria-label').toLowerCase();
      if (text && label.indexOf(text) < 0) { el.removeAttribute('aria-label'); }
    });
    // the colour-mode button shows one icon whose title names the mode: its name says both
    document.querySelectorAll('.theme-switch-button').forEach(function (el) {
      var shown = Array.from(el.querySelectorAll('svg, i')).filter(function (i) { return i.getBoundingClientRect().width > 0; });
      var title = shown.length ? (shown[0].querySelector('title') || shown[0]).textContent || shown[0].getAttribute('title') : '';
      el.setAttribute('aria-label', 'Color mode' + (title ? ': ' + title.trim() : ''));
      if (!el.dataset.orrcNamed) {
        el.dataset.orrcNamed = '1';
        el.addEventListener('click', function () { setTimeout(names, 0); });
      }
    });
    document.querySelectorAll('li.has-children > details > summary').forEach(function (el) {
      if (el.hasAttribute('aria-label')) { return; }
      var link = el.parentElement.parentElement.querySelector(':scope > a');
      el.setAttribute('aria-label', 'Sections of ' + (link ? link.textContent.trim() : 'this page'));
    });
  }
  function all() { mark(); names(); }
  window.orrcMarkOverflow = all;
  function start() {
    all();
    if (window.MathJax && MathJax.startup && MathJax.startup.promise) {
      MathJax.startup.promise.then(mark);
    }
    var timer;
    window.addEventListener('resize', function () { clearTimeout(timer); timer = setTimeout(mark, 100); });
  }
  if (document.readyState === 'loading') { document.addEventListener('DOMContentLoaded', start); } else { start(); }
  window.addEventListener('load', function () { all(); setTimeout(all, 0); });
})();
