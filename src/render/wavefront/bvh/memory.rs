//! Memory advice for the tree's arrays: transparent huge pages for large trees.

/// `v` moved into memory advised for 2 MiB transparent huge pages (Linux, arrays of at least
/// 4 MiB), else `v` itself. A deep ray through a 1M-triangle tree touches nodes and blocks
/// spread over 65 MB: in 4 KiB pages a TLB miss at almost every level, in 2 MiB pages 33
/// entries cover it all (Embree's BVH gets huge pages too; under THP mode `madvise`, nothing
/// else in raywave does). Only a hint: where the kernel declines, the copy is a plain copy.
/// +2–4% on 1M-triangle rays against a tree without the advice (docs/TRIED.md, "The mesh BVH").
pub(super) fn huge_pages<T: Copy>(v: Vec<T>) -> Vec<T> {
    #[cfg(target_os = "linux")]
    {
        /// Arrays at least this large go to memory advised for transparent huge pages.
        const HUGE_PAGE_MIN_BYTES: usize = 4 << 20;
        const HUGE: usize = 2 << 20;
        let bytes = std::mem::size_of_val(v.as_slice());
        if bytes >= HUGE_PAGE_MIN_BYTES {
            // glibc maps an allocation this large afresh (mmap), untouched, so advising it
            // before the copy lets its first page faults take huge pages; from an allocator
            // that reuses touched memory, the advice only lets khugepaged collapse it later.
            let mut out = Vec::with_capacity(v.len());
            let base = out.as_mut_ptr() as usize;
            let (start, end) = (base.next_multiple_of(HUGE), (base + bytes) & !(HUGE - 1));
            if end > start {
                // SAFETY: [start, end) lies inside `out`'s allocation, and MADV_HUGEPAGE only
                // changes how the kernel backs those pages, never their contents.
                unsafe {
                    libc::madvise(start as *mut libc::c_void, end - start, libc::MADV_HUGEPAGE);
                }
            }
            out.extend_from_slice(&v);
            return out;
        }
    }
    v
}
