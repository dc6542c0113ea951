// Wide blocks scroll in their own box with a visible cue (tools/sphinx_a11y.py): every display
// equation, code block and table wider than its box gets the class orrc-overflows (a scroll bar
// and a shadow on the side where more content waits), tabindex=0 and a region label, so that a
// keyboard can scroll it too. Re-checked when the window is resized and after MathJax typesets.
(function () {
  var SELECTOR = 'div.math, mjx-container[display="true"], div.highlight pre, .cell_output pre, ' +
                 'div.pst-scrollable-table-container, .table-wrapper';
  function label(el) {
    if (el.matches('div.math, mjx-container')) { return 'equation, scrolls sideways'; }
    if (el.matches('pre')) { return 'code, scrolls sideways'; }
    return 'table, scrolls sideways';
  }
  function edges(el) {
    el.classList.toggle('orrc-more-left', el.scrollLeft > 1);
    el.classList.toggle('orrc-more-right', el.scrollLeft + el.clientWidth < el.scrollWidth - 1);
  }
  function mark() {
    document.querySelectorAll(SELECTOR).forEach(function (el) {
      var over = el.scrollWidth > el.clientWidth + 1;
      el.classList.toggle('orrc-overflows', over);
      if (over) {
        if (!el.hasAttribute('tabindex')) { el.setAttribute('tabindex', '0'); el.dataset.orrcTab = '1'; }
        if (!el.hasAttribute('role')) { el.setAttribute('role', 'region'); el.dataset.orrcRole = '1'; }
        if (!el.hasAttribute('aria-label')) { el.setAttribute('aria-label', label(el)); el.dataset.orrcLabel = '1'; }
        if (!el.dataset.orrcScroll) {
          el.dataset.orrcScroll = '1';
          el.addEventListener('scroll', function () { edges(el); }, {passive: true});
        }
        edges(el);
      } else {
        if (el.dataset.orrcTab) { el.removeAttribute('tabindex'); delete el.dataset.orrcTab; }
        if (el.dataset.orrcRole) { el.removeAttribute('role'); delete el.dataset.orrcRole; }
        if (el.dataset.orrcLabel) { el.removeAttribute('aria-label'); delete el.dataset.orrcLabel; }
        el.classList.remove('orrc-more-left', 'orrc-more-right');
      }
    });
  }
  window.orrcMarkOverflow = mark;
  function start() {
    mark();
    if (window.MathJax && MathJax.startup && MathJax.startup.promise) {
      MathJax.startup.promise.then(mark);
    }
    var timer;
    window.addEventListener('resize', function () { clearTimeout(timer); timer = setTimeout(mark, 100); });
  }
  if (document.readyState === 'loading') { document.addEventListener('DOMContentLoaded', start); } else { start(); }
  window.addEventListener('load', mark);
})();
