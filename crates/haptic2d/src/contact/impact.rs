//! Simultaneous impacts with Poisson restitution (§7): Delassus assembly, compression LCP, restitution, plastic correction.
