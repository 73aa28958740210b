//! The little-endian encoding of a study shard's `shard.bin`
//! (`crate::shard::study`): lengths and counts as u64, every f64 as its
//! bits (infinities, NaN and -0.0 read back as written). Each approach
//! encodes its own pairs with these (`slide`, `direct`); the shard's file
//! holds them.
//!
//! **Invariant:** reading is bounds-checked: a cut or damaged file is an
//! error, never a panic, and a count larger than the bytes left allocates
//! nothing.

pub(crate) fn put_u64(out: &mut Vec<u8>, v: u64) {
    out.extend_from_slice(&v.to_le_bytes());
}

pub(crate) fn put_f64(out: &mut Vec<u8>, v: f64) {
    put_u64(out, v.to_bits());
}

pub(crate) fn put_f64s(out: &mut Vec<u8>, v: &[f64]) {
    put_u64(out, v.len() as u64);
    for &x in v {
        put_f64(out, x);
    }
}

pub(crate) fn put_opt(out: &mut Vec<u8>, v: Option<f64>) {
    out.push(u8::from(v.is_some()));
    put_f64(out, v.unwrap_or(0.0));
}

pub(crate) fn put_points(out: &mut Vec<u8>, v: &[[f64; 2]]) {
    put_u64(out, v.len() as u64);
    for p in v {
        put_f64(out, p[0]);
        put_f64(out, p[1]);
    }
}

pub(crate) fn put_nodes(out: &mut Vec<u8>, v: &[(usize, usize)]) {
    put_u64(out, v.len() as u64);
    for &(i, j) in v {
        put_u64(out, i as u64);
        put_u64(out, j as u64);
    }
}

/// Reads `shard.bin`; every read checks the bytes left, and a length
/// never exceeds them (a damaged length cannot make a huge allocation).
pub(crate) struct Reader<'a> {
    bin: &'a [u8],
    /// Bytes read so far.
    pub(crate) at: usize,
}

impl<'a> Reader<'a> {
    /// A reader of `bin` from its start.
    pub(crate) fn new(bin: &'a [u8]) -> Reader<'a> {
        Reader { bin, at: 0 }
    }

    pub(crate) fn take(&mut self, n: usize) -> Result<&[u8], String> {
        let end = self
            .at
            .checked_add(n)
            .filter(|&e| e <= self.bin.len())
            .ok_or("it ends early")?;
        let bytes = &self.bin[self.at..end];
        self.at = end;
        Ok(bytes)
    }

    pub(crate) fn u8(&mut self) -> Result<u8, String> {
        Ok(self.take(1)?[0])
    }

    pub(crate) fn u64(&mut self) -> Result<u64, String> {
        let b = self.take(8)?;
        Ok(u64::from_le_bytes(b.try_into().map_err(|_| "8 bytes")?))
    }

    pub(crate) fn f64(&mut self) -> Result<f64, String> {
        Ok(f64::from_bits(self.u64()?))
    }

    /// A count of items of at least `size` bytes each still to come.
    pub(crate) fn count(&mut self, size: usize) -> Result<usize, String> {
        let n = self.u64()?;
        let left = (self.bin.len() - self.at) / size.max(1);
        usize::try_from(n)
            .ok()
            .filter(|&n| n <= left)
            .ok_or_else(|| format!("a count of {n} where {left} at most fit"))
    }

    pub(crate) fn len(&mut self) -> Result<usize, String> {
        usize::try_from(self.u64()?).map_err(|_| "a length beyond memory".to_string())
    }

    pub(crate) fn f64s(&mut self) -> Result<Vec<f64>, String> {
        let n = self.count(8)?;
        (0..n).map(|_| self.f64()).collect()
    }

    pub(crate) fn opt(&mut self) -> Result<Option<f64>, String> {
        let some = match self.u8()? {
            0 => false,
            1 => true,
            b => return Err(format!("an option flag {b}")),
        };
        let v = self.f64()?;
        Ok(some.then_some(v))
    }

    pub(crate) fn bools(&mut self) -> Result<Vec<bool>, String> {
        let n = self.count(1)?;
        (0..n)
            .map(|_| match self.u8()? {
                0 => Ok(false),
                1 => Ok(true),
                b => Err(format!("a flag {b}")),
            })
            .collect()
    }

    pub(crate) fn points(&mut self) -> Result<Vec<[f64; 2]>, String> {
        let n = self.count(16)?;
        (0..n).map(|_| Ok([self.f64()?, self.f64()?])).collect()
    }

    pub(crate) fn nodes(&mut self) -> Result<Vec<(usize, usize)>, String> {
        let n = self.count(16)?;
        (0..n).map(|_| Ok((self.len()?, self.len()?))).collect()
    }
}
