// MathJax for pymdownx.arithmatex (generic mode): the \( \) and \[ \] it writes, typeset again on each page
// that Material's instant navigation loads; read by the vendored bundle after it (mathjax/tex-svg.js, mkdocs.yml).
window.MathJax = {
  tex: {inlineMath: [["\\(", "\\)"]], displayMath: [["\\[", "\\]"]], processEscapes: true, processEnvironments: true},
  options: {ignoreHtmlClass: ".*|", processHtmlClass: "arithmatex"}
};
if (typeof document$ !== "undefined") {
  document$.subscribe(() => { MathJax.startup.output.clearCache(); MathJax.typesetClear(); MathJax.texReset();
                              MathJax.typesetPromise(); });
}
