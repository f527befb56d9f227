// Every figure of a gallery example opens full size on click (readable on a phone: zoom the image itself).
document.addEventListener("DOMContentLoaded", function () {
  document.querySelectorAll("img.sphx-glr-single-img, img.sphx-glr-multi-img").forEach(function (img) {
    if (img.closest("a")) { return; }
    var link = document.createElement("a");
    link.href = img.getAttribute("src");
    link.title = "open the figure full size";
    img.parentNode.insertBefore(link, img);
    link.appendChild(img);
  });
});
