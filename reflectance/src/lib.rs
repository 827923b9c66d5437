//! The flowed reflectance field as data (to be built by the reflectance issue): per pose
//! and view, 26 premultiplied linear basis images, alpha and flows to each grid
//! neighbour, plus per-pose shadow attenuation maps; the signed-logarithmic 8-bit flow
//! quantizer with canonical Huffman coding; the gamma-2.2 JPEG basis mosaic; the indexed,
//! checksummed container; projection of HDR environments onto the basis; and CPU
//! relighting. Conventions: [`frf_core::conventions`].
