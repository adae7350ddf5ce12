//! Large zeroed buffers of plain values (texture levels, shadow maps)
//! backed by transparent huge pages where the system offers them.
//!
//! A frame reads its texture maps and shadow maps all over: a 1024² RGBA
//! map is 4 MiB, a thousand 4 KiB pages, and three maps of a material
//! plus their mip levels miss the processor's page-translation cache
//! (TLB) on many texel reads. A buffer of 2 MiB or more is therefore
//! allocated 2 MiB-aligned, rounded up to whole 2 MiB pages, and on Linux
//! advised as `MADV_HUGEPAGE` before it is first written, so that the
//! kernel backs it with 2 MiB pages where transparent huge pages are
//! enabled (`always` or `madvise`, the usual default); elsewhere the
//! advice is ignored and the buffer is ordinary memory. Smaller buffers
//! are plain 64-byte-aligned allocations.

use std::alloc::{self, Layout};
use std::ptr::NonNull;

/// The huge page size of x86-64 and most arm64 kernels.
const HUGE_PAGE: usize = 2 << 20;

/// A fixed-length, zero-initialised buffer of `T`.
pub struct BigBuf<T: bytemuck::Pod> {
    ptr: NonNull<T>,
    len: usize,
    /// The allocation (None for an empty buffer, which allocates nothing).
    layout: Option<Layout>,
}

// SAFETY: a BigBuf owns its allocation exclusively, like a Vec<T>; T is
// plain data.
unsafe impl<T: bytemuck::Pod + Send> Send for BigBuf<T> {}
// SAFETY: shared references only read, as for a Vec<T>.
unsafe impl<T: bytemuck::Pod + Sync> Sync for BigBuf<T> {}

impl<T: bytemuck::Pod> BigBuf<T> {
    /// `len` zeroed values. Panics, as `vec!` does, where the size
    /// overflows the address space; aborts where memory runs out.
    pub fn zeroed(len: usize) -> BigBuf<T> {
        let bytes = len
            .checked_mul(size_of::<T>())
            .expect("buffer size overflows");
        if bytes == 0 {
            return BigBuf {
                ptr: NonNull::dangling(),
                len,
                layout: None,
            };
        }
        let huge = bytes >= HUGE_PAGE;
        let (size, align) = if huge {
            (bytes.next_multiple_of(HUGE_PAGE), HUGE_PAGE)
        } else {
            (bytes, align_of::<T>().max(64))
        };
        let layout = Layout::from_size_align(size, align).expect("buffer size overflows");
        // SAFETY: the layout's size is not zero.
        let p = unsafe { alloc::alloc(layout) };
        let Some(ptr) = NonNull::new(p) else {
            alloc::handle_alloc_error(layout)
        };
        #[cfg(target_os = "linux")]
        if huge {
            // SAFETY: [p, p + size) is this allocation and p is page
            // aligned; the call only advises the kernel (it neither reads
            // nor writes the memory) and its failure changes nothing.
            unsafe {
                libc::madvise(p.cast(), size, libc::MADV_HUGEPAGE);
            }
        }
        // SAFETY: the allocation holds `size` bytes; all-zero bytes are a
        // valid T (Pod).
        unsafe { std::ptr::write_bytes(p, 0, size) };
        BigBuf {
            ptr: ptr.cast(),
            len,
            layout: Some(layout),
        }
    }

    /// A copy of `values`.
    pub fn from_slice(values: &[T]) -> BigBuf<T> {
        let mut b = BigBuf::zeroed(values.len());
        b.copy_from_slice(values);
        b
    }
}

impl<T: bytemuck::Pod> std::ops::Deref for BigBuf<T> {
    type Target = [T];
    #[inline(always)]
    fn deref(&self) -> &[T] {
        // SAFETY: ptr points to len initialised values (or is dangling
        // with len * size_of::<T>() == 0), owned by self.
        unsafe { std::slice::from_raw_parts(self.ptr.as_ptr(), self.len) }
    }
}

impl<T: bytemuck::Pod> std::ops::DerefMut for BigBuf<T> {
    #[inline(always)]
    fn deref_mut(&mut self) -> &mut [T] {
        // SAFETY: as in `deref`, and &mut self is the only access.
        unsafe { std::slice::from_raw_parts_mut(self.ptr.as_ptr(), self.len) }
    }
}

impl<T: bytemuck::Pod> Drop for BigBuf<T> {
    fn drop(&mut self) {
        if let Some(layout) = self.layout {
            // SAFETY: allocated in `zeroed` with this layout.
            unsafe { alloc::dealloc(self.ptr.as_ptr().cast(), layout) };
        }
    }
}

impl<T: bytemuck::Pod> Default for BigBuf<T> {
    /// Empty.
    fn default() -> BigBuf<T> {
        BigBuf::zeroed(0)
    }
}

impl<T: bytemuck::Pod> From<Vec<T>> for BigBuf<T> {
    fn from(v: Vec<T>) -> BigBuf<T> {
        BigBuf::from_slice(&v)
    }
}

impl<T: bytemuck::Pod> FromIterator<T> for BigBuf<T> {
    fn from_iter<I: IntoIterator<Item = T>>(it: I) -> BigBuf<T> {
        BigBuf::from_slice(&it.into_iter().collect::<Vec<T>>())
    }
}

impl<T: bytemuck::Pod> Clone for BigBuf<T> {
    fn clone(&self) -> BigBuf<T> {
        BigBuf::from_slice(self)
    }
}

impl<T: bytemuck::Pod> std::fmt::Debug for BigBuf<T> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "BigBuf({} values)", self.len)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zeroed_writable_and_aligned() {
        for len in [
            0usize,
            1,
            1000,
            (HUGE_PAGE / 4) - 1,
            HUGE_PAGE / 4,
            HUGE_PAGE + 3,
        ] {
            let mut b = BigBuf::<u32>::zeroed(len);
            assert_eq!(b.len(), len);
            assert!(b.iter().all(|&x| x == 0));
            for (i, x) in b.iter_mut().enumerate() {
                *x = i as u32;
            }
            let c = b.clone();
            assert!(c.iter().enumerate().all(|(i, &x)| x == i as u32));
            if len > 0 {
                let align = if len * 4 >= HUGE_PAGE { HUGE_PAGE } else { 64 };
                assert_eq!(b.as_ptr() as usize % align, 0, "{len}");
            }
        }
        let empty = BigBuf::<[u8; 64]>::from_slice(&[]);
        assert!(empty.is_empty());
    }
}
