"use strict";
// Sort the results by any column (click its head; again to reverse) and filter by text.
(function () {
  var table = document.getElementById("results");
  var body = table.tBodies[0];
  var heads = Array.prototype.slice.call(table.tHead.rows[0].cells);
  var rows = Array.prototype.slice.call(body.rows);
  var filter = document.getElementById("filter");
  var shown = document.getElementById("shown");
  function value(row, col) {
    var cell = row.cells[col];
    var v = cell.hasAttribute("data-sort") ? cell.getAttribute("data-sort") : cell.textContent.trim();
    return v !== "" && !isNaN(Number(v)) ? Number(v) : v.toLowerCase();
  }
  function order(a, b) {  // numbers before text; blanks are placed by the caller
    if (typeof a !== typeof b) return typeof a === "number" ? -1 : 1;
    return a < b ? -1 : a > b ? 1 : 0;
  }
  heads.forEach(function (th, col) {
    th.querySelector("button").addEventListener("click", function () {
      var dir = th.getAttribute("aria-sort") === "ascending" ? -1 : 1;
      heads.forEach(function (h) { h.removeAttribute("aria-sort"); });
      th.setAttribute("aria-sort", dir === 1 ? "ascending" : "descending");
      rows.slice().sort(function (r, s) {
        var a = value(r, col), b = value(s, col);
        if (a === "" || b === "") return (a === "") - (b === "");  // missing values last, either way
        return dir * order(a, b);
      }).forEach(function (r) { body.appendChild(r); });
    });
  });
  filter.addEventListener("input", function () {
    var q = filter.value.trim().toLowerCase(), n = 0;
    rows.forEach(function (r) {
      r.hidden = r.textContent.toLowerCase().indexOf(q) < 0;
      n += r.hidden ? 0 : 1;
    });
    shown.textContent = n + " of " + rows.length + " videos shown";
  });
})();
