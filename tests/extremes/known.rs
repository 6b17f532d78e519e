//! Cases of the sweep unstable today because of bugs not fixed yet: each with what goes wrong and
//! the audit's finding as measured (frame and value). None at present: every case ends stable or
//! refused with a typed error. The sweep fails when one of them becomes
//! stable or refused (remove it then), and when a case not listed is unstable, so the list can
//! only shrink as the bugs are fixed.

/// A known failure: the case's label as the table prints it, what goes wrong, the value measured.
pub struct Known {
    /// The case.
    pub case: &'static str,
    /// What goes wrong.
    pub what: &'static str,
    /// The audit's first finding, as measured.
    pub measured: &'static str,
}

/// Every known failure.
pub const KNOWN: &[Known] = &[];
