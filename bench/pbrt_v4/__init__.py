"""pbrt-v4 as a peer: the same pbrt-v4 file rendered by mcrt and by pbrt-v4
itself (built from source by build.sh), compared per channel, per 8x8 block
and in efficiency. See README.md."""
