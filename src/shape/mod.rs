//! Reference elements: the node numbering, Lagrange shape functions `N_a`, their natural
//! gradients and the quadrature of the 10-node tetrahedron and the 27-node hexahedron. Pure
//! functions of reference coordinates; meshes number their nodes by them and elements integrate
//! with them.

pub mod hex27;
pub mod tet10;
